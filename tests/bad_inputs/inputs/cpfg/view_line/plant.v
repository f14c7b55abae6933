line: l leaf.s 1
