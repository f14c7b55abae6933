line style: cylinder
background scene: scene.dat
