initial line width: 0.1
line style: cylinder
background scene: background.dat
