/* Mipmapped and blended textures on a flat 3 x 3 square (tests/model/cpfg_texture_test.cpp
   derives every colour by hand). quads.png is 4 x 4 texels, top row first:
     R B G G
     B R G G
     W W B B
     W W B B
   so its mip level 1 (2 x 2, each texel the mean of four, in the file's sRGB values) is
   purple (0.5, 0, 0.5), green, white and blue, and level 2 (1 x 1) is (0.375, 0.5, 0.625).
   cutout.png is 5 x 1 red texels of alpha 255, 0, 128, 26 and 25 (of 255). */
angle increment: 90
line style: cylinder
surface: a flat.s 3 2 2
texture: F: quads.png H: n L: m S    /* GL_LINEAR_MIPMAP_LINEAR (trilinear) */
texture: F: quads.png H: n L: mnn S  /* GL_NEAREST_MIPMAP_NEAREST */
texture: F: quads.png E: b S         /* GL_BLEND: the colour times 1 - texel */
texture: F: cutout.png E: b          /* GL_BLEND keeps the texel's alpha: cut out as modulate */
texture: F: cutout.png L: m          /* 5 x 1: scaled to 4 x 1 first (GLU) */
