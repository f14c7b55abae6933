angle increment: 22
