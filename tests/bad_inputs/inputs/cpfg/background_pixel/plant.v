background scene: scene.dat
