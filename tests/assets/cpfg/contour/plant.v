angle increment: 90
initial line width: 0.4
line style: cylinder
contour sides: 6
contour: 1 blade.con
contour: 2 strip.con
