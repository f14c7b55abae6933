angle increment: 30
angel factor: 8
