angle increment: 30
surface: l leaf.s 1
