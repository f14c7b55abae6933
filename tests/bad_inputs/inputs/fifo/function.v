angle increment: 30
function: width.func
