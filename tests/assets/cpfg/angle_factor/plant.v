angle factor: 8
initial line width: 0.2 shaded
