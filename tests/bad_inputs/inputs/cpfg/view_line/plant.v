line: l leaf.s
