tropism direction: 0,0,0
initial elasticity: 0.2
