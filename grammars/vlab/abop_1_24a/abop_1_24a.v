angle increment: 25.7
