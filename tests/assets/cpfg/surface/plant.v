angle increment: 90
initial line width: 0.1
line style: cylinder
surface: a plate.s 6 3 2
