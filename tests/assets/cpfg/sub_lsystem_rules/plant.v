angle increment: 90
initial line width: 0.2
line style: cylinder
