initial line width: 1 shaded
