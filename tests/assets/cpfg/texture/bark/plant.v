/* A branching plant with a bark texture on its cylinders (docs/GRAMMAR.md, "Textures").
   bark.png (written by make_bark.py) repeats around and along a branch; cpfg keeps its
   texels square: t grows by length / (pi * width) times the image's width / height. */
angle factor: 16
line style: cylinder
contour sides: 12
texture: F: bark.png H: l L: l E: d
