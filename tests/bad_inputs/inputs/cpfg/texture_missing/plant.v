texture: F: missing.png
