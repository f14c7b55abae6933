executable: sprig_enviro_test field
communication type: memory
turtle position:%.5f %.5f %.5f
following module: no
