angle increment: 90
function: ignored.func
function set: plant.fset
