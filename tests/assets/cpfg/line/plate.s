1 4  0 3  0 9
PRECISION S: 7 T: 9
CONTACT POINT  X: 1 Y: 0 Z: 0
END POINT  X: 1 Y: 3 Z: 0
HEADING  X: 0 Y: 1 Z: 0
UP  X: 0 Y: 0 Z: 1
SIZE: 3
plate
TOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00
AL: ~ A: ~ AR: ~
L: ~ R: ~
BL: ~ B: ~ BR: ~
1 0 0  2 0 0  3 0 0  4 0 0
1 1 0  2 1 1  3 1 2  4 1 3
1 2 0  2 2 2  3 2 4  4 2 6
1 3 0  2 3 3  3 3 6  4 3 9
