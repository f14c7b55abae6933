surface: l leaf.s 1 6 4
