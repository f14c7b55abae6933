/* Textures on a flat 3 x 3 square surface (tests/model/tree_kind_test.cpp derives every
   texture coordinate and colour by hand). halves.png is 2 x 1 texels: red, then blue. */
angle increment: 90
line style: cylinder
surface: a flat.s 3 2 2
surface: b flat.s 3 2 2 1
texture: F: halves.png H: n L: n E: d /* per patch, laid over the colour */
texture: F: halves.png H: n L: l E: m S /* one image over the surface, times the colour */
