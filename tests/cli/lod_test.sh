#!/usr/bin/env bash
# `sprig mesh` levels of detail end to end (registered with ctest as `cli_mesh_lod`):
#   1. a tree in leaf with `--lod 8000`: the .glb's scene is LOD0 (wood and leaves), each
#      part node carries MSFT_lod (in extensionsUsed, not extensionsRequired) whose ids name
#      PART_lodK nodes outside the scene, with MSFT_screencoverage of one value per level;
#      triangles per level strictly decrease, LOD0 within the budget; STEM_lodK.glb (K from
#      0) and STEM_lodK.obj (K from 1) exist, with the same part names and each level's
#      triangles;
#   2. `--lod none` writes the one file with the full mesh (the PCM junction's 11,044
#      triangles, the export without levels of detail) and
#      no level's file, while the default (`auto`) writes its three levels and their files;
#   3. a blob (no levels by default) writes its one file as before.
# Usage: tests/cli/lod_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"

# tree_lime at step 2, cell 0.04: 10,880 triangles (wood 10,656, leaves 224), 9 s.
"$SPRIG" mesh species/tree_lime.yaml --steps 2 --cell 0.04 --lod 8000 -o "$WORK/t.glb" -o "$WORK/t.obj" >"$WORK/t.out"
grep -qF "levels of detail (LOD0 budget 8000 triangles, full mesh 10880)" "$WORK/t.out" || fail "no levels note: $(cat "$WORK/t.out")"
python3 - "$WORK" 8000 <<'PY' || fail "levels of detail: $(cat "$WORK/t.out")"
import json, os, struct, sys
work, budget = sys.argv[1], int(sys.argv[2])

def glb(path):
    data = open(path, 'rb').read()
    n = struct.unpack_from('<I', data, 12)[0]
    return json.loads(data[20:20 + n])

def tris(g, node):
    return sum(g['accessors'][p['indices']]['count'] // 3 for p in g['meshes'][g['nodes'][node]['mesh']]['primitives'])

g = glb(os.path.join(work, 't.glb'))
assert g['extensionsUsed'] == ['MSFT_lod'] and 'extensionsRequired' not in g, g.get('extensionsUsed')
top = g['scenes'][0]['nodes']
names = [g['nodes'][i]['name'] for i in top]
assert names == ['wood', 'leaves'], names
ids = [g['nodes'][i]['extensions']['MSFT_lod']['ids'] for i in top]
n = len(ids[0]) + 1
assert n >= 3 and all(len(x) == n - 1 for x in ids), ids
for i, x in zip(top, ids):
    cov = g['nodes'][i]['extras']['MSFT_screencoverage']
    assert cov == [0.25 ** (k + 1) for k in range(n - 1)] + [0], cov
    for k, j in enumerate(x, 1):
        assert g['nodes'][j]['name'] == g['nodes'][i]['name'] + '_lod%d' % k and j not in top
per_level = [sum(tris(g, i) for i in top)] + [sum(tris(g, x[k]) for x in ids) for k in range(n - 1)]
assert per_level[0] <= budget, per_level
assert all(a > b for a, b in zip(per_level, per_level[1:])), per_level
for k in range(n):
    f = glb(os.path.join(work, 't_lod%d.glb' % k))
    assert 'extensionsUsed' not in f
    assert [nd['name'] for nd in f['nodes']] == names
    assert sum(tris(f, i) for i in f['scenes'][0]['nodes']) == per_level[k], (k, per_level)
    obj = os.path.join(work, 't.obj' if k == 0 else 't_lod%d.obj' % k)
    lines = open(obj).read().split('\n')
    assert [l[2:] for l in lines if l.startswith('o ')] == names
    assert sum(l.startswith('f ') for l in lines) == per_level[k], (obj, per_level)
assert not os.path.exists(os.path.join(work, 't_lod0.obj'))
assert not os.path.exists(os.path.join(work, 't_lod%d.glb' % n))
print('levels', per_level)
PY

# The full mesh one flag away: today's triangles, one file; by default three levels.
mkdir "$WORK/full" "$WORK/auto"
"$SPRIG" mesh species/fig_tree_12_pcm_offset.yaml --lod none -o "$WORK/full/j.glb" >"$WORK/full.out"
grep -qF "$WORK/full/j.glb: 11044 triangles," "$WORK/full.out" || fail "--lod none: $(cat "$WORK/full.out")"
[ "$(ls "$WORK/full")" = j.glb ] || fail "--lod none wrote $(ls "$WORK/full")"
if grep -q "levels of detail\|MSFT_lod" "$WORK/full.out" "$WORK/full/j.glb"; then fail "--lod none made levels"; fi
"$SPRIG" mesh species/fig_tree_12_pcm_offset.yaml -o "$WORK/auto/j.glb" >"$WORK/auto.out"
grep -qF "full mesh 11044): LOD0 11044 " "$WORK/auto.out" || fail "default levels: $(cat "$WORK/auto.out")"
[ "$(ls "$WORK/auto" | tr '\n' ' ')" = "j.glb j_lod0.glb j_lod1.glb j_lod2.glb " ] || fail "default files: $(ls "$WORK/auto")"
cmp -s "$WORK/full/j.glb" "$WORK/auto/j_lod0.glb" || fail "LOD0 of a model within the budget is not the full mesh"

# Blobs have no levels by default.
mkdir "$WORK/blob"
"$SPRIG" mesh species/blob_ricci_fig3.yaml -o "$WORK/blob/b.glb" >/dev/null
[ "$(ls "$WORK/blob")" = b.glb ] || fail "a blob wrote $(ls "$WORK/blob")"
# A part that keeps its own image (single-bark wood) has normal maps on coordinates of their
# own: the .glb holds them, the OBJ cannot, and says so.
mkdir "$WORK/own"
"$SPRIG" mesh species/tree_scarred.yaml --steps 2 --cell 0.04 --lod 1000 -o "$WORK/own/s.obj" -o "$WORK/own/s.glb" >"$WORK/own.out"
grep -qF "$WORK/own/s.obj: no normal maps for wood: OBJ gives a corner one uv" "$WORK/own.out" || fail "no OBJ normal-map note: $(cat "$WORK/own.out")"
if grep -q "s.glb: no normal maps" "$WORK/own.out"; then fail "the .glb was said to lack normal maps"; fi
if ls "$WORK/own" | grep -q normal; then fail "an OBJ normal map was written: $(ls "$WORK/own")"; fi
echo "mesh level-of-detail tests passed"
