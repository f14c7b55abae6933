/* Cut-out textures on a flat 3 x 3 square (tests/model/cpfg_texture_test.cpp derives every
   hit by hand). cutout.png is 5 x 1 red texels of alpha 255, 0, 128, 26 and 25 (of 255):
   cpfg draws a fragment whose alpha is above 0.1 (glAlphaFunc(GL_GREATER, 0.1)) blended
   by its alpha, and leaves out the rest. */
angle increment: 90
surface: a flat.s 3 2 2
texture: F: cutout.png E: m /* modulate: the texel's alpha is the fragment's */
texture: F: cutout.png E: d /* decal: the texel's alpha blends the colours; the fragment is opaque */
