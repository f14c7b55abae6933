#!/usr/bin/env bash
# `sprig schema` checked by an independent validator, ajv-cli (registered with ctest as
# `cli_schema`; scripts/install-deps.sh installs it into tools/ajv):
#   1. the schema is valid draft-07 JSON Schema, and ajv's strict mode prints no warning;
#   2. every shipped species file (species/*.yaml, also accepted by `sprig check`) is valid;
#   3. files the reader rejects for an unknown key, a wrong type, a value out of range, a
#      wrong word or colour, a missing or unknown kind (tests/bad_inputs and a few edits of
#      shipped species) are rejected by the schema too, and the same edits within range are
#      accepted by both; so are unknown keys inside blob nodes (also nested in a blend),
#      solids' distance fields (also in a union), layers and operations, and bad values
#      inside the entries of maps whose keys are data (a solid's materials, a tree's
#      defines) and inside a shell's generating primitives (point, cone).
# Usage: tests/cli/schema_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
SPRIG=$(realpath "$1")
AJV=$(pwd)/tools/ajv/node_modules/.bin/ajv
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-schema-test-XXXXXX")
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
[ -x "$AJV" ] || fail "ajv-cli is not installed: run scripts/install-deps.sh"
# ajv in its default strict mode, told of the two editor message keywords the schema carries
# (scripts/ajv/editor-keywords.js); the documented run (docs/EDITORS.md).
ajv() { local c=$1; shift; "$AJV" "$c" "$@" --spec=draft7 -c "$(pwd)/scripts/ajv/editor-keywords.js" $([ "$c" = validate ] && echo --errors=line); }

"$SPRIG" -q schema -o "$WORK/schema.json"
"$SPRIG" schema | cmp -s - "$WORK/schema.json" || fail "schema on stdout differs from -o"
ajv compile -s "$WORK/schema.json" > "$WORK/compile.out" 2>&1 || { cat "$WORK/compile.out"; fail "the schema does not compile"; }
# 1b. Strict mode has nothing to say: no warning, only the success line.
[ "$(cat "$WORK/compile.out")" = "schema $WORK/schema.json is valid" ] || { cat "$WORK/compile.out"; fail "ajv's strict mode warns"; }

# 2. Every shipped species.
# One validator run for all of them (each start of Node.js costs about a second here).
n=$(ls species/*.yaml | wc -l)
[ "$n" -ge 50 ] || fail "only $n species files"
ajv validate -s "$WORK/schema.json" -d "species/*.yaml" > "$WORK/out" 2>&1 || { grep -v " valid$" "$WORK/out"; fail "species valid for sprig but not for the schema"; }
[ "$(grep -c ' valid$' "$WORK/out")" -eq "$n" ] || { cat "$WORK/out"; fail "ajv did not report all $n species valid"; }

# 3. Rejected by both the reader and the schema.
rejected=(unknown_key wrong_type wrong_section_type out_of_range bad_choice bad_color missing_kind unknown_kind
          nan_value inf_value organism_bad_procedure three_sections)
# Files the schema must accept or reject, validated together at the end by one ajv process
# (it compiles the schema once: a process per file took minutes): "FILE valid|invalid WHAT".
expected=()
for c in "${rejected[@]}"; do
  f=tests/bad_inputs/inputs/$c.yaml
  if "$SPRIG" -q check "$f" > /dev/null 2>&1; then fail "sprig accepts $f"; fi
  expected+=("$f invalid $f")
done
# Edits, one key each, of a small tree species and of shipped species: TEXT appended, and
# whether both must accept or both reject it.
mkdir -p "$WORK/lib/species"
cp -r grammars "$WORK/lib/"
# fig_shell_07a names its pair (render.pair), which must be there too.
cp species/fig_shell_07a_varix_spines.yaml species/fig_shell_07a2_varix_tori.yaml species/blob_ricci_fig3.yaml "$WORK/lib/species/"
printf 'kind: tree\ngrammar: ../grammars/abop_1_24a.lsys\n' > "$WORK/lib/species/tree.yaml"
edits=0
both() {  # both SPECIES 'yaml text to append' valid|invalid  (the schema's verdict comes at the end)
  local src=$1 edit=$2 want=$3 f="$WORK/lib/species/case_$edits.yaml"
  { cat "$WORK/lib/species/$src.yaml"; echo "$edit"; } > "$f"
  local r=0
  (cd "$WORK/lib" && "$SPRIG" -q --root . check "species/case_$edits.yaml" > /dev/null 2>&1) || r=1
  if [ "$want" = valid ]; then
    [ "$r" -eq 0 ] || fail "$src + '$edit': sprig rejects it"
  else
    [ "$r" -eq 1 ] || fail "$src + '$edit': sprig accepts it"
  fi
  expected+=("$f $want $src + '$edit'")
  edits=$((edits + 1))
}
both tree 'max_modules: 1000' valid
both tree 'max_modules: 0' invalid
both tree 'seeed: 3' invalid
both tree 'turtle: {tropism: [0, -1, 0], elasticity: 0.2}' valid
both tree 'turtle: {elasticity: 20}' invalid
both tree 'turtle: {tropism: [0, -1]}' invalid
both tree 'turtle: {radii: pipe, pipe_exponent: 2.5}' valid
both tree 'turtle: {radii: pipe, pipe_exponent: 20}' invalid
both tree 'render: {width: 10}' invalid
both tree 'render: {sun: {elevation: 0.5}}' invalid
both tree 'render: {wood: "#5b3f28", view: {fov: 40}, ground: false}' valid
both tree 'render: {wood: "#5b3f2"}' invalid
both tree 'render: {background: colour}' invalid
both fig_shell_07a_varix_spines 'stages: [1, 2]' valid
both fig_shell_07a_varix_spines 'stages: [1, -2]' invalid
both blob_ricci_fig3 'kernel: soft' valid
both blob_ricci_fig3 'kernel: smooth' invalid
# Keys inside the parts the readers walk themselves (one-key maps): blob nodes, nested in
# blends; solids' distance fields, nested in unions; operations.
printf 'kind: blob\n' > "$WORK/lib/species/blobbase.yaml"
printf 'kind: solid\n' > "$WORK/lib/species/solidbase.yaml"
sphere='volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}'
both blobbase 'blob: {point: {radius: 1}}' valid
both blobbase 'blob: {point: {radius: 1, colour: 2}}' invalid
both blobbase 'blob: {blend: [{point: {radius: 1}}, {point: {radius: 1, center: [0, 0, 0]}}]}' valid
both blobbase 'blob: {blend: [{point: {radius: 1}}, {point: {radius: 1, centre: [0, 0, 0]}}]}' invalid
both blobbase 'blob: {cone: {a: [0, 0, 0], b: [0, 1, 0], radius: 0.2, offset_radius: -1}}' invalid
both blobbase 'blob: {blob: {radius: 1}}' invalid
both solidbase "solid: {$sphere}" valid
both solidbase 'solid: {volume: {distance_field: {sphere: {radius: 1, radious: 2}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {union: [{sphere: {radius: 1}}, {box: {size: [1, 1, 1]}}]}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' valid
both solidbase 'solid: {volume: {distance_field: {union: [{sphere: {radius: 1}}, {box: {size: [1, 1, 1], sise: 2}}]}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {material: wood, thickness: fill, colour: 1}}]}}' invalid
both solidbase "solid: {$sphere, operations: [{hammer: {rounds: 2}}]}" valid
both solidbase "solid: {$sphere, operations: [{hammer: {rounds: 2, strength: 1}}]}" invalid
both solidbase "solid: {$sphere, operations: [{polish: {shiny: 0.5}}, {dirt: {amount: 0.5, colour: 1}}]}" invalid
# Required keys inside parts (the readers' own checks, recorded as `required`): one key
# missing per part kind, each beside a twin that has it.
printf 'kind: organism\n' > "$WORK/lib/species/orgbase.yaml"
both blobbase 'blob: {cone: {a: [0, 0, 0], b: [0, 1, 0], radius: 0.2}}' valid
both blobbase 'blob: {cone: {a: [0, 0, 0], radius: 0.2}}' invalid
both blobbase 'blob: {scale: {factors: 2, child: {point: {radius: 1}}}}' valid
both blobbase 'blob: {scale: {child: {point: {radius: 1}}}}' invalid
both blobbase 'blob: {controlled: {groups: chain, children: [{point: {radius: 1}}, {point: {radius: 1}}]}}' valid
both blobbase 'blob: {controlled: {groups: chain}}' invalid
both blobbase 'blob: {controlled: {children: [{point: {radius: 1}}, {point: {radius: 1}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {transform: {distance_field: {sphere: {radius: 1}}}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' valid
both solidbase 'solid: {volume: {distance_field: {transform: {}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {thickness: fill}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {extrude_2d: {size: [1, 1]}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' invalid
both solidbase 'solid: {volume: {distance_field: {species: {seed: 1}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' invalid
both solidbase "solid: {$sphere, operations: [{displace: {offset: [0, 0.1, 0]}}]}" invalid
both orgbase 'organism: {base: {revolution: {profile: "0.5"}}}' valid
both orgbase 'organism: {base: {revolution: {}}}' invalid
both orgbase 'organism: {base: {mesh: {}}}' invalid
both orgbase 'organism: {base: {cube_sphere: {radius: 1}}, blend: {alpha: {plane: {normal: [1, 0, 0]}}}}' valid
both orgbase 'organism: {base: {cube_sphere: {radius: 1}}, blend: {}}' invalid
both orgbase 'organism: {base: {cube_sphere: {radius: 1}}, modify: [{gains: [1]}]}' valid
both orgbase 'organism: {base: {cube_sphere: {radius: 1}}, modify: [{radius: 1}]}' invalid
# Keys whose names are data: a solid's materials (each entry a concrete or a procedural
# material), a tree's defines (each a number), a shell's generating primitives ({point: ...}
# or {cone: ...}): a bad value inside an entry is found by both.
printf 'kind: shell\n' > "$WORK/lib/species/shellbase.yaml"
printf 'kind: tree\ngrammar: ../grammars/abop_2_6.lsys\n' > "$WORK/lib/species/treedefs.yaml"
oak='solid: {volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {material: oak, thickness: fill}}]}}'
both solidbase "$oak
materials: {oak: {base: wood, color: [0.5, 0.3, 0.2], roughness: 0.4}, mix: {select: \"x > 0\", choices: [oak, stone]}}" valid
both solidbase "$oak
materials: {oak: {color: [0.5, 0.3, 0.2], roughness: 2}}" invalid
both solidbase "$oak
materials: {oak: {colour: [0.5, 0.3, 0.2]}}" invalid
both solidbase "$oak
materials: {oak: {color: [0.5, 0.3, 2]}}" invalid
both solidbase "$oak
materials: {oak: 3}" invalid
both treedefs 'defines: {r1: 0.8, a0: 30}' valid
both treedefs 'defines: {r1: short}' invalid
prims() { echo "shell: {generating: {primitives: [$1]}}"; }
both shellbase "$(prims '{point: {center: [0, 0, 0], radius: 0.75}}, {cone: {a: [-0.1, 0.2, 0], b: [-2.25, 3.6, 0], radius_a: 0.7, radius_b: 0.15, bend: 20}}')" valid
both shellbase "$(prims '{point: {center: [0, 0, 0], radius: 0}}')" invalid
both shellbase "$(prims '{point: {centre: [0, 0, 0], radius: 0.75}}')" invalid
both shellbase "$(prims '{point: {center: [0, 0], radius: 0.75}}')" invalid
both shellbase "$(prims '{cone: {a: [-0.1, 0.2, 0], b: [-2.25, 3.6, 0], bend: 200}}')" invalid
both shellbase "$(prims '{cone: {a: [-0.1, 0.2, 0], b: [-2.25, 3.6, 0], canal: maybe}}')" invalid
both shellbase "$(prims '{sphere: {radius: 1}}')" invalid
both shellbase "$(prims '{point: {radius: 1}, cone: {radius_a: 1}}')" invalid
# What the schema cannot express: a name that must refer to something else in the file.
# A solid layer's material is any word to the schema (JSON Schema cannot check that a
# string names a key of another map, here 'materials:' or the built-in table); sprig check
# rejects an unknown one with its position.
both solidbase 'solid: {volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {material: wood, thickness: fill}}]}}' valid
f="$WORK/lib/species/case.yaml"
{ cat "$WORK/lib/species/solidbase.yaml"
  echo 'solid: {volume: {distance_field: {sphere: {radius: 1}}, layers: [{interior_layer: {material: woood, thickness: fill}}]}}'; } > "$f"
ajv validate -s "$WORK/schema.json" -d "$f" > /dev/null 2>&1 || fail "the schema rejects an unknown material name (it cannot know the names)"
if (cd "$WORK/lib" && "$SPRIG" -q --root . check species/case.yaml > "$WORK/out" 2>&1); then fail "sprig check accepts material 'woood'"; fi
grep -q "species/case.yaml:2:.*error:.*woood" "$WORK/out" || { cat "$WORK/out"; fail "sprig check does not name the unknown material at its line"; }
# The schema's verdict on every queued file, from one ajv run.
args=()
for e in "${expected[@]}"; do args+=(-d "${e%% *}"); done
ajv validate -s "$WORK/schema.json" "${args[@]}" > "$WORK/out" 2>&1 || true
for e in "${expected[@]}"; do
  read -r f want what <<< "$e"
  grep -qxF "$f $want" "$WORK/out" || {
    grep -A3 -F "$f " "$WORK/out" >&2
    fail "$what: the schema does not find it $want"
  }
done
echo "schema: ok ($n shipped species valid, ${#rejected[@]} bad inputs and $edits edits agree with sprig)"
