angle increment: 90
curve: profile.con
curve: arch.con 50
curve: loop.con
curve: ends.con 20
curve: phantom.con
