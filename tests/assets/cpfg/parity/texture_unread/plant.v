texture: F: not_here.png H:n L:n E:m
