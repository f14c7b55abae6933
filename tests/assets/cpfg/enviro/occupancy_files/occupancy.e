executable: sprig_enviro_test occupancy 1
communication type: files 7
turtle position:P:%.4f %.4f %.0f
