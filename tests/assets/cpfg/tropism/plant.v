tropism: T: 0 -2 0 E: 0.2
