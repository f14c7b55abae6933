background scene: ground.dat
