surface: a flat.s 1
texture: F: halves.png
