tropism: T: 0 -1 0 E: 0.1 S: 0.2
