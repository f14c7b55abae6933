texture: F: halves.png L: mx
