/* Textured cylinders and generalized cylinders (tests/model/cpfg_texture_test.cpp derives
   every texture coordinate by hand). quadrants.png is 4 x 2 texels: the bottom row (t below
   1/2) red, green, blue, white along s; the top row cyan, magenta, yellow, black. */
angle increment: 90
line style: cylinder
texture: F: quadrants.png E: d
