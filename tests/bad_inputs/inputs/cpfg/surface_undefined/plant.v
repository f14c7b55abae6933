angle increment: 30
surface: a plate.s 1
tsurface: b bract.ts
