0 3  0 3  0 0
PRECISION S: 1 T: 1
CONTACT POINT  X: 0 Y: 0 Z: 0
END POINT  X: 0 Y: 3 Z: 0
HEADING  X: 0 Y: 1 Z: 0
UP  X: 0 Y: 0 Z: 1
SIZE: 3
square
TOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00
AL: ~ A: ~ AR: ~
L: ~ R: ~
BL: ~ B: ~ BR: ~
0 0 0  1 0 0  2 0 0  3 0 0
0 1 0  1 1 0  2 1 0  3 1 0
0 2 0  1 2 0  2 2 0  3 2 0
0 3 0  1 3 0  2 3 0  3 3 0
