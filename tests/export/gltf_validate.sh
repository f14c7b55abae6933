#!/usr/bin/env bash
# Every kind's .glb export read back by the Khronos glTF validator (scripts/gltf-validate.js):
# no errors, no warnings; and its parts and colours checked against the species file by
# scripts/gltf-parts.py (node names, baseColorFactor, double-sided leaves). One species of
# each kind, of each part type (wood + leaves, whorl + varices + inside, solid materials)
# and of each organism base and colouring. A shell's separate 'spines' part (the axial canal
# spines of fig_shell_09a/09b and the Murex) is baked and written by the same code as the
# varices; its export takes minutes (a million triangles), so it is not among these cases.
# Levels of detail (MSFT_lod) are validated on three trees and an organism (the PCM tree and the
# organism with the detail maps of their simplified levels: normalTexture and TANGENT; the lime
# in leaf, whose last two levels' leaves are alpha-tested leaf cards and crown cards); the
# other cases write the full mesh alone (--lod none), which is what each level is made from.
# Usage: gltf_validate.sh path/to/sprig   (run from the repository root)
set -euo pipefail
sprig="$1"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# species  [parts it must have; *part: with a baked baseColorTexture]  (flags after '|')
species=(
  "abop_1_24a wood | --steps 3 --lod auto"  # tree, skeleton of an L-system, with its levels of detail
  "fig_tree_12_pcm_offset wood"             # tree, BlobTree with PCM, bark off: no image
  "tree_lime wood leaves | --steps 3 --cell 0.01 --wind 6,45"  # tree in leaf: wood and double-sided leaves apart (bark per girth: vertex colours); wind: morph targets and the animation 'wind'; every tree: _WIND
  "tree_scarred *wood | --steps 4"        # one bark for every cone: baked into an image
  "tree_scarred *wood | --steps 3 --lod 2000"  # its levels keep the image (TEXCOORD_0) and get a normal map of their own coordinates (TEXCOORD_1)
  "shell_top *whorl inside"                 # shell, painted pigment
  "fig_shell_07b_varix_full *whorl varices" # shell with varices and their spines
  "blob_ricci_fig3 blob"                   # blob
  "fig_org_05b_berry_level2 organism | --lod 20000"  # organism on a primitive, with its levels of detail and their detail maps (a small budget: the bake follows the levels' texels)
  "fig_tree_12_pcm_offset wood | --lod 2000"  # tree with PCM ridges: both levels simplified, each with a normal map and TANGENT
  "tree_lime wood leaves | --steps 3 --cell 0.02 --lod 2000"  # tree in leaf with levels: the leaves of the last two levels are alpha-tested cards (leaf cards, then crown cards)
  "fig_org_13a_mummified_skull_sharp organism"  # organism on a CT volume, blend colour
  "fig_org_14c_planet_blend organism"      # organism with the planet shader
  "org_painted_band organism"              # organism on a painted mesh
  "fig_solid_01_striped_candy chocolate white_chocolate"  # solid: one part per material
  "fig_tree_12_pcm_offset wood | --mesher dual"  # dual marching cubes
  "shell_top whorl inside | --mesher dual"
  "shell_top whorl inside | --mesher dual --simplify 1e-3"  # simplified parts keep their borders
)
files=()
for entry in "${species[@]}"; do
  read -r s parts <<<"${entry%%|*}"
  flags=""
  [[ "$entry" == *"|"* ]] && flags="${entry#*|}"
  # shellcheck disable=SC2086
  f="$out/$s.${#files[@]}.glb"
  [[ "$flags" == *--lod* ]] || flags+=" --lod none"
  "$sprig" mesh "species/$s.yaml" -o "$f" $flags >/dev/null
  files+=("$f")
  expect=()
  for p in $parts; do
    if [[ "$p" == \** ]]; then expect+=(--textured "${p#\*}"); else expect+=(--expect "$p"); fi
  done
  python3 scripts/gltf-parts.py "species/$s.yaml" "$f" "${expect[@]}"
  if [[ "$s" == fig_tree_12_pcm_offset && "$flags" == *--lod\ 2000* ]]; then
    # Every level is simplified: each material has a normal map, each primitive its TANGENT.
    python3 - "$f" <<'PY'
import json, struct, sys
d = open(sys.argv[1], 'rb').read()
j = json.loads(d[20:20 + struct.unpack('<I', d[12:16])[0]])
prims = [p for m in j['meshes'] for p in m['primitives']]
bad = [p for p in prims if 'normalTexture' not in j['materials'][p['material']] or 'TANGENT' not in p['attributes']]
if len(prims) < 2 or bad:
    sys.exit('%s: %d of %d primitives without a normal map and TANGENT' % (sys.argv[1], len(bad), len(prims)))
PY
  fi
  if [[ "$s" == tree_scarred && "$flags" == *--lod\ 2000* ]]; then
    # Every level: the bark image through TEXCOORD_0, a normal map through TEXCOORD_1.
    python3 - "$f" <<'PY'
import json, struct, sys
d = open(sys.argv[1], 'rb').read()
j = json.loads(d[20:20 + struct.unpack('<I', d[12:16])[0]])
prims = [p for m in j['meshes'] for p in m['primitives']]
def ok(p):
    m = j['materials'][p['material']]
    return m.get('normalTexture', {}).get('texCoord') == 1 and 'TEXCOORD_1' in p['attributes'] \
        and m['pbrMetallicRoughness']['baseColorTexture'].get('texCoord', 0) == 0
if len(prims) < 2 or not all(map(ok, prims)):
    sys.exit('%s: a level without its image and a normal map of its own coordinates' % sys.argv[1])
PY
  fi
  if [[ "$s" == tree_lime && "$flags" == *--lod\ 2000* ]]; then
    # The last two levels' leaves (leaf cards, then crown cards): quads (4 vertices, 2
    # triangles each), alphaMode MASK with an alphaCutoff and a baseColorTexture, fewer on
    # the crown level; the wood is there too.
    python3 - "$f" <<'PY'
import json, struct, sys
d = open(sys.argv[1], 'rb').read()
j = json.loads(d[20:20 + struct.unpack('<I', d[12:16])[0]])
levels = {}
for n in j['nodes']:
    if 'mesh' in n and '_lod' in n['name']:
        part, k = n['name'].split('_lod')
        levels.setdefault(part, {})[int(k)] = n
leaves, wood = levels.get('leaves', {}), levels.get('wood', {})
if len(leaves) < 2 or not wood:
    sys.exit('%s: no two lower levels of leaves and a level of wood' % sys.argv[1])
counts = []
for k in sorted(leaves)[-2:]:
    p = j['meshes'][leaves[k]['mesh']]['primitives'][0]
    m = j['materials'][p['material']]
    tris, verts = j['accessors'][p['indices']]['count'] // 3, j['accessors'][p['attributes']['POSITION']]['count']
    if m.get('alphaMode') != 'MASK' or m.get('alphaCutoff', 0.5) <= 0 or 'baseColorTexture' not in m['pbrMetallicRoughness'] \
            or tris == 0 or verts != 2 * tris:
        sys.exit('%s: leaves_lod%d are not cards: %s, %d triangles, %d vertices' % (sys.argv[1], k, m, tris, verts))
    counts.append(tris)
if counts[1] >= counts[0]:
    sys.exit('%s: the crown level has no fewer card triangles than the leaf cards: %s' % (sys.argv[1], counts))
PY
  fi
done
# A cpfg object whose texture cuts out (alphaMode MASK with alphaCutoff, an RGBA PNG, nearest
# samplers) beside an opaque decal one.
f="$out/cpfg_cutout.${#files[@]}.glb"
"$sprig" mesh tests/assets/cpfg/texture/cutout -o "$f" >/dev/null
files+=("$f")
# cpfg's textured tubes: F cylinders and generalized cylinders as textured_wood parts with
# TEXCOORD_0 (t beyond 1: the image repeats along the branch); every segment is textured,
# so there is no BlobTree 'wood' part.
for o in cylinder bark; do
  f="$out/cpfg_$o.${#files[@]}.glb"
  "$sprig" mesh "tests/assets/cpfg/texture/$o" -o "$f" >/dev/null
  files+=("$f")
done
node scripts/gltf-validate.js "${files[@]}"
