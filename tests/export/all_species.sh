#!/usr/bin/env bash
# Every shipped species exported to .glb, read by the Khronos glTF validator (0 errors,
# 0 warnings) and checked for its parts and colours (scripts/gltf-parts.py). Too slow for
# CI (the PCM poplar alone is 7 M triangles); tests/export/gltf_validate.sh is the CI subset.
# Usage: all_species.sh path/to/sprig [OUTDIR]   (run from the repository root)
set -euo pipefail
sprig="$1"
out="${2:-$(mktemp -d)}"
mkdir -p "$out"
bad=0
# Trees last: they are the biggest meshes (millions of triangles each).
mapfile -t files < <(grep -L '^kind: tree' species/*.yaml; grep -l '^kind: tree' species/*.yaml)
for f in "${files[@]}"; do
  s="$(basename "$f" .yaml)"
  if ! "$sprig" --quiet mesh "$f" -o "$out/$s.glb" >"$out/$s.log" 2>&1; then
    echo "$s: sprig mesh failed"; cat "$out/$s.log"; bad=1; continue
  fi
  python3 scripts/gltf-parts.py "$f" "$out/$s.glb" || bad=1
  node scripts/gltf-validate.js "$out/$s.glb" || bad=1
  rm -f "$out/$s.glb" "$out/${s}"_lod*.glb  # and its levels of detail
done
exit $bad
