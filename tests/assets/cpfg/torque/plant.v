torque: T: 1 0 0 E: 0.5
