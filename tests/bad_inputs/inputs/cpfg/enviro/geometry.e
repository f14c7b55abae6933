executable: sprig_enviro_test field
interpreted modules: F
