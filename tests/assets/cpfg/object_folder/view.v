angle factor: 12
