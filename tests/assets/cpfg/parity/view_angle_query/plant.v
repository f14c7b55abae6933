angle increment: 30
angle increment: ?
