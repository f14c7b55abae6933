angle increment: 90
function: a.func
function: b.func 5
function: c.func 100
