torque: T: 0 1 0 E: 0.1
