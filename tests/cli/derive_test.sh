#!/usr/bin/env bash
# `sprig derive` end to end (registered with ctest as `cli_derive`):
#   1. `--json` on ABOP figure 1.24a prints exactly the documented keys in order, with
#      ABOP's numbers at n = 5: 7811 modules, 3125 segments (internodes), total length 3125,
#      symbol counts F 3125, + 781, - 781, [ 1562, ] 1562, end [0, 243, 0];
#   2. the numbers follow --steps and -D, and `--print` writes a string that is re-read equal;
#   3. determinism: the same stochastic grammar and seed give the same bytes (stdout of
#      --print and --json, the --skeleton file) in two runs and at --threads 1, 2 and 0,
#      and a different seed gives different bytes;
#   4. a species file and its bare grammar agree on the derivation;
#   5. cpfg: a vlab object folder is read through its `specifications` (tree.l with view.v's
#      angle factor 12, i.e. 30 degrees: 3 internodes, the top at 1 + cos 30), and a bare
#      `.l` without a view file draws with cpfg's 45 degrees and says so in a note; cpfg's
#      printf writes to stderr.
# Usage: tests/cli/derive_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"

# --- 1. the --json report of ABOP 1.24a --------------------------------------------------
json=$(sprig derive grammars/abop_1_24a.lsys --json)
echo "$json" | grep -q '^{"steps": 5, "modules": 7811, "symbols": {' || fail "1.24a json head: $json"
keys=$(echo "$json" | grep -o '"[a-z_]*": ' | tr -d '": ' | tr '\n' ' ')
# Top-level keys in order (symbol names are not lower-case words), with bounds' min/max.
[ "$keys" = "steps modules symbols internodes total_length bounds min max end " ] || fail "1.24a json keys: $keys"
# 5^5 F; every one of the 1+5+25+125+625 = 781 rewrites adds one + and one - and two [ ].
echo "$json" | grep -qF '"symbols": {"F": 3125, "+": 781, "-": 781, "[": 1562, "]": 1562}' ||
  fail "1.24a symbol counts: $json"
echo "$json" | grep -q '"internodes": 3125, "total_length": 3125, "bounds": {"min": \[' || fail "1.24a internodes/length: $json"
echo "$json" | grep -q '"end": \[0, 243, 0\]}$' || fail "1.24a end (the main axis is 3^5 = 243 F straight up): $json"

# --- 2. --steps, -D and --print ---------------------------------------------------------
json3=$(sprig derive grammars/abop_1_24a.lsys --json --steps 3)
echo "$json3" | grep -q '^{"steps": 3, "modules": 311, ' || fail "1.24a n=3: $json3"
echo "$json3" | grep -q '"internodes": 125, "total_length": 125,' || fail "1.24a n=3 segments: $json3"
sprig derive grammars/abop_1_24a.lsys --print --steps 1 >"$WORK/p1" || fail "--print failed"
[ "$(cat "$WORK/p1")" = "F[+F]F[-F]F" ] || fail "--print at n=1: $(cat "$WORK/p1")"
# ABOP 2.6: -D changes the numbers (r1 scales the trunk), not the module count.
m_a=$(sprig derive grammars/abop_2_6.lsys --json | grep -o '"modules": [0-9]*')
m_b=$(sprig derive grammars/abop_2_6.lsys --json -D r1=0.5 | grep -o '"modules": [0-9]*')
[ "$m_a" = "$m_b" ] || fail "-D changed the module count: $m_a vs $m_b"
l_a=$(sprig derive grammars/abop_2_6.lsys --json | grep -o '"total_length": [0-9.e+-]*')
l_b=$(sprig derive grammars/abop_2_6.lsys --json -D r1=0.5 | grep -o '"total_length": [0-9.e+-]*')
[ "$l_a" != "$l_b" ] || fail "-D r1=0.5 did not change the total length ($l_a)"

# --- 3. determinism -----------------------------------------------------------------------
G=tests/assets/lsystem/stochastic_bush.lsys
run_all() {  # $1: tag, rest: global flags
  local tag=$1; shift
  "$SPRIG" --quiet "$@" derive "$G" --print --json --skeleton "$WORK/$tag.skel.json" >"$WORK/$tag.out"
}
run_all a
run_all b
run_all t1 --threads 1
run_all t2 --threads 2
run_all t0 --threads 0
for t in b t1 t2 t0; do
  cmp -s "$WORK/a.out" "$WORK/$t.out" || fail "stdout differs between run a and $t"
  cmp -s "$WORK/a.skel.json" "$WORK/$t.skel.json" || fail "skeleton differs between run a and $t"
done
[ -s "$WORK/a.skel.json" ] || fail "empty skeleton file"
grep -q '"internodes": \[' "$WORK/a.skel.json" || fail "skeleton file has no internodes"
"$SPRIG" --quiet derive "$G" --print --json --seed 43 >"$WORK/s43.out"
! cmp -s "$WORK/a.out" "$WORK/s43.out" || fail "--seed 43 gave the same string as seed 42"
"$SPRIG" --quiet derive "$G" --print --json --seed 42 >"$WORK/s42.out"
cmp -s "$WORK/a.out" "$WORK/s42.out" || fail "--seed 42 differs from the grammar's own seed: 42"

# --- 4. species file and bare grammar ------------------------------------------------------
# species/abop_1_24a.yaml names the same grammar at the same n.
js=$(sprig derive species/abop_1_24a.yaml --json | grep -o '^{"steps": [0-9]*, "modules": [0-9]*')
[ "$js" = '{"steps": 5, "modules": 7811' ] || fail "species/abop_1_24a.yaml: $js"

# --- 5. cpfg objects ------------------------------------------------------------------------
jo=$(sprig derive tests/assets/cpfg/object_folder --json)
echo "$jo" | grep -q '^{"steps": 2, "modules": 25, ' || fail "vlab folder: $jo"
echo "$jo" | grep -q '"internodes": 3, "total_length": 3, ' || fail "vlab folder internodes: $jo"
echo "$jo" | grep -q '"max": \[0.55[0-9]*, 1.926025403784438[0-9]*, 0.06\]' || fail "vlab folder: not 30 degrees: $jo"
"$SPRIG" derive tests/assets/cpfg/no_view/plant.l --json >"$WORK/nv.out" 2>"$WORK/nv.err" || fail "no_view/plant.l failed"
grep -q '"end": \[-0.7071067811865475, 1.7071067811865475, 0\]}$' "$WORK/nv.out" || fail "no view file: not 45 degrees: $(cat "$WORK/nv.out")"
grep -qF "tests/assets/cpfg/no_view/plant.l: note: no view file 'plant.v' beside it: using cpfg's defaults: angle increment 45," "$WORK/nv.err" ||
  fail "no note about cpfg's defaults: $(cat "$WORK/nv.err")"

# printf in statement blocks writes to stderr (tests/assets/cpfg/printf/plant.l's comment).
"$SPRIG" --quiet derive tests/assets/cpfg/printf/plant.l --print >"$WORK/pf.out" 2>"$WORK/pf.err" || fail "printf/plant.l failed"
[ "$(cat "$WORK/pf.out")" = "A(3.5)" ] || fail "printf object string: $(cat "$WORK/pf.out")"
[ "$(cat "$WORK/pf.err")" = "$(printf 'A 1.5 -> 3 (50%%)\nA 2.5 -> 5 (50%%)\ndone after 2 steps')" ] || fail "printf output: $(cat "$WORK/pf.err")"

# cpfg's 'line:' defines a surface and leaves F as it was: derived, printed and drawn
# (skeleton JSON); a malformed one stops --print too, as a view file error does in cpfg.
"$SPRIG" --quiet derive tests/assets/cpfg/line/plant.l --print >"$WORK/ln.out" 2>"$WORK/ln.err" ||
  fail "--print of a view file with 'line:' failed: $(cat "$WORK/ln.err")"
[ "$(cat "$WORK/ln.out")" = "F(2)~L" ] || fail "'line:' object string: $(cat "$WORK/ln.out")"
"$SPRIG" --quiet derive tests/assets/cpfg/line/plant.l >/dev/null 2>"$WORK/ln.err" ||
  fail "derive (drawn) of a view file with 'line:' failed: $(cat "$WORK/ln.err")"
if "$SPRIG" --quiet derive tests/bad_inputs/inputs/cpfg/view_line/plant.l --print >/dev/null 2>&1; then
  fail "--print of a view file with a malformed 'line:' did not fail"
fi

echo "cli_derive: all checks passed"
