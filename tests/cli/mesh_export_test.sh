#!/usr/bin/env bash
# `sprig mesh` exports end to end (registered with ctest as `cli_mesh_export`):
#   1. several outputs from one run: `-o a.glb -o b.obj` writes both (and the OBJ's MTL),
#      the glb and the OBJ carry the same triangles, the run builds and bakes once (the
#      texture notes are printed once, and the timings of the two-output run are those of
#      one build), a repeated path and a volume mesh beside a surface are refused;
#   2. placement: the model stands on y = 0 (the lowest vertex of the glb's POSITION
#      accessors and of the OBJ's `v` lines is 0 within 1e-6) and is centred in x and z,
#      for a tree, a shell and an organism.
# Usage: tests/cli/mesh_export_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"

# The glb's triangle count and its box (min and max of every POSITION accessor) of the
# scene's nodes (LOD0; lower levels of detail are nodes outside the scene), and the same
# from the OBJ's f and v lines: "triangles minx miny minz maxx maxy maxz".
glb_stats() {
  python3 - "$1" <<'PY'
import json, struct, sys
data = open(sys.argv[1], 'rb').read()
n = struct.unpack_from('<I', data, 12)[0]
g = json.loads(data[20:20 + n])
tris, lo, hi = 0, [1e30] * 3, [-1e30] * 3
for m in (g['meshes'][g['nodes'][i]['mesh']] for i in g['scenes'][0]['nodes']):
    for p in m['primitives']:
        tris += g['accessors'][p['indices']]['count'] // 3
        a = g['accessors'][p['attributes']['POSITION']]
        lo = [min(x, y) for x, y in zip(lo, a['min'])]
        hi = [max(x, y) for x, y in zip(hi, a['max'])]
assert all('translation' not in node and 'matrix' not in node for node in g['nodes'])
print(tris, *lo, *hi)
PY
}
obj_stats() {
  awk '$1 == "f" { t++ } $1 == "v" { for (i = 0; i < 3; i++) { x = $(i + 2) + 0; if (!(i in lo) || x < lo[i]) lo[i] = x; if (!(i in hi) || x > hi[i]) hi[i] = x } }
       END { print t, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2] }' "$1"
}
# Standing on y = 0 within 1e-6 and centred in x and z (within 1e-5 of the extent).
check_placed() {
  python3 - "$1" "$2" <<'PY' || fail "$2 not placed at the origin: $1"
import sys
t, x0, y0, z0, x1, y1, z1 = map(float, sys.argv[1].split())
ext = max(x1 - x0, y1 - y0, z1 - z0)
assert t > 0 and abs(y0) <= 1e-6 and y1 > 0, (y0, y1)
assert abs(x0 + x1) <= 1e-5 * ext and abs(z0 + z1) <= 1e-5 * ext, (x0, x1, z0, z1)
PY
}

for entry in "fig_tree_12_pcm_offset" "fig_shell_10_opening_cut --cell 0.1" "fig_org_05b_berry_level2"; do
  read -r s flags <<<"$entry"
  # shellcheck disable=SC2086
  "$SPRIG" mesh "species/$s.yaml" -o "$WORK/$s.glb" -o "$WORK/$s.obj" $flags >"$WORK/$s.out"
  for f in "$s.glb" "$s.obj" "$s.mtl"; do [ -s "$WORK/$f" ] || fail "$s: $f not written"; done
  grep -qF "$WORK/$s.glb, $WORK/$s.obj: " "$WORK/$s.out" || fail "$s: one summary for both files: $(cat "$WORK/$s.out")"
  g=$(glb_stats "$WORK/$s.glb")
  o=$(obj_stats "$WORK/$s.obj")
  [ "${g%% *}" = "${o%% *}" ] || fail "$s: glb has ${g%% *} triangles, OBJ ${o%% *}"
  check_placed "$g" "$s.glb"
  check_placed "$o" "$s.obj"
done
# The shell's textures are baked once: one note per textured part, as with one output.
"$SPRIG" mesh species/fig_shell_10_opening_cut.yaml -o "$WORK/one.glb" --cell 0.1 >"$WORK/one.out"
[ "$(grep -c 'baked from' "$WORK/fig_shell_10_opening_cut.out")" = "$(grep -c 'baked from' "$WORK/one.out")" ] ||
  fail "bake notes differ: $(cat "$WORK/fig_shell_10_opening_cut.out")"
[ "$(grep -c 'baked from' "$WORK/one.out")" -ge 1 ] || fail "no bake note: $(cat "$WORK/one.out")"
cmp -s "$WORK/one.glb" "$WORK/fig_shell_10_opening_cut.glb" || fail "the glb of a two-output run differs from a one-output run's"

# Refused before any work, nothing written.
mkdir "$WORK/bad"
if "$SPRIG" mesh species/shell_top.yaml -o "$WORK/bad/a.glb" -o "$WORK/bad/a.glb" 2>"$WORK/err"; then fail "a repeated -o passed"; fi
grep -qF "is given twice" "$WORK/err" || fail "repeated -o message: $(cat "$WORK/err")"
if "$SPRIG" mesh species/solid_layered_sphere.yaml -o "$WORK/bad/a.glb" -o "$WORK/bad/a.msh" 2>"$WORK/err"; then fail "glb + msh passed"; fi
grep -qF "several outputs are surface meshes" "$WORK/err" || fail "glb + msh message: $(cat "$WORK/err")"
[ -z "$(ls -A "$WORK/bad")" ] || fail "files left: $(ls "$WORK/bad")"
echo "mesh export tests passed"
