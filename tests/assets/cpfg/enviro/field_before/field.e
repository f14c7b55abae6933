executable: sprig_enviro_test field
communication type: pipes 3
turtle position:P:%g %g %g
turtle heading:H: %.3f %.3f %.3f
