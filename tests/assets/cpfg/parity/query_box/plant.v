angle factor: 4
box: x: -4,4 y: -2,7 z:-4,4
