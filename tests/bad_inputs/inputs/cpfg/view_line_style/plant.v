line style: 7
