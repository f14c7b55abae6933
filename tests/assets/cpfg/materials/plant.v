angle increment: 45
initial line width: 0.1
line style: cylinder
