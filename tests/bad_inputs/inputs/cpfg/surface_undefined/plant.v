angle increment: 30
surface: a plate.s 1
