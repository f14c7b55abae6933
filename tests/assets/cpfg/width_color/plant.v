initial line width: 4
line width increment: 1
initial color: 5
color increment: 2
