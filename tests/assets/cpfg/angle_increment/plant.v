/* only turtle settings and viewer settings */
angle increment: 30
viewpoint: 0,0,1
projection: parallel
