angle increment: 25
