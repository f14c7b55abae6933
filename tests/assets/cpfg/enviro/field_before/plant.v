angle increment: 25
environment display: before
