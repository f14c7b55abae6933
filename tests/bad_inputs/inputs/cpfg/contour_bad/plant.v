initial line width: 0.2
line style: cylinder
contour: 1 leaf.con
