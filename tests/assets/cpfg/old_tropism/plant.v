tropism direction: 0,-3,0
initial elasticity: 0
elasticity increment: 0.5
