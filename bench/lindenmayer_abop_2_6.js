// ABOP figure 2.6a (grammars/abop_2_6.lsys) derived by the `lindenmayer` npm package: the
// baseline of bench/startup.sh. Prints "<steps> steps, <modules> modules" so the bench can
// check that Sprig's `derive` wrote the same number of modules.
//
//   node bench/lindenmayer_abop_2_6.js STEPS MODULE_DIR
//
// MODULE_DIR is the folder holding node_modules/lindenmayer (installed by bench/startup.sh).
'use strict';
const path = require('path');

const steps = parseInt(process.argv[2] || '10', 10);
const moduleDir = process.argv[3] || '.';
const LSystem = require(path.join(path.resolve(moduleDir), 'node_modules', 'lindenmayer'));

// The grammar's #defines (figure 2.6a).
const r1 = 0.9, r2 = 0.6, a0 = 45, a2 = 45, d = 137.5, wr = 0.707;
const m = (symbol, ...params) => ({symbol, params});

const lsystem = new LSystem({
  axiom: [m('A', 1, 10)],
  productions: {
    // A(l,w) : * --> !(w)F(l)[&(a0)B(l*r2,w*wr)]/(d)A(l*r1,w*wr)
    A: ({part}) => {
      const [l, w] = part.params;
      return [m('!', w), m('F', l), m('['), m('&', a0), m('B', l * r2, w * wr), m(']'), m('/', d), m('A', l * r1, w * wr)];
    },
    // B(l,w) : * --> !(w)F(l)[-(a2)$C(l*r2,w*wr)]C(l*r1,w*wr)
    B: ({part}) => {
      const [l, w] = part.params;
      return [m('!', w), m('F', l), m('['), m('-', a2), m('$'), m('C', l * r2, w * wr), m(']'), m('C', l * r1, w * wr)];
    },
    // C(l,w) : * --> !(w)F(l)[+(a2)$B(l*r2,w*wr)]B(l*r1,w*wr)
    C: ({part}) => {
      const [l, w] = part.params;
      return [m('!', w), m('F', l), m('['), m('+', a2), m('$'), m('B', l * r2, w * wr), m(']'), m('B', l * r1, w * wr)];
    },
  },
});

lsystem.iterate(steps);
console.log(`${steps} steps, ${lsystem.getRaw().length} modules`);
