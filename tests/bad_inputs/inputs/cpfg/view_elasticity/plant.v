tropism direction: 0,-1,0
initial elasticity: 0.2
