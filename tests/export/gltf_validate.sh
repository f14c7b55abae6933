#!/usr/bin/env bash
# Every kind's .glb export read back by the Khronos glTF validator (scripts/gltf-validate.js):
# no errors, no warnings. One species of each kind and of each organism base and colouring.
# Usage: gltf_validate.sh path/to/sprig   (run from the repository root)
set -euo pipefail
sprig="$1"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
species=(
  abop_1_24a                 # tree, skeleton of an L-system
  fig_tree_12_pcm_offset     # tree, BlobTree with PCM
  shell_top                  # shell, painted pigment
  blob_ricci_fig3            # blob
  fig_org_05b_berry_level2   # organism on a primitive
  fig_org_13a_mummified_skull_sharp  # organism on a CT volume, blend colour
  fig_org_14c_planet_blend   # organism with the planet shader
  org_painted_band           # organism on a painted mesh
)
files=()
for s in "${species[@]}"; do
  "$sprig" mesh "species/$s.yaml" -o "$out/$s.glb" >/dev/null
  files+=("$out/$s.glb")
done
node scripts/gltf-validate.js "${files[@]}"
