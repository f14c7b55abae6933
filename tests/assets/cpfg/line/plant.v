initial line width: 0.1
line style: cylinder
line: L plate.s 4 2 2
