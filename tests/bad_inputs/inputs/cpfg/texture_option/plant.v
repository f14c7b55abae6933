texture: F: halves.png E: b
