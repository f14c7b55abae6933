#!/usr/bin/env bash
# A tree's wind in Blender (docs/MESHES.md "Wind"): a small tree exported with --wind, then
# imported by Blender's own glTF importer (scripts/blender-wind.py): every part with morph
# targets must come in with its shape keys and an action from the animation 'wind'; and a
# tree exported with --wind 0 must have none (the script exits 1). 35 s on the loaded 2-core
# machine (two exports, Blender started twice). Usage: blender_wind.sh path/to/sprig   (run from the repository root)
set -euo pipefail
sprig="$1"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$sprig" mesh species/abop_1_24a.yaml --steps 3 --lod none --wind 5,90 -o "$out/wind.glb" >/dev/null
blender -b --factory-startup --python scripts/blender-wind.py -- "$out/wind.glb" >"$out/wind.log" 2>&1 || {
  cat "$out/wind.log"; echo "blender_wind: Blender did not import the wind's shape keys and action"; exit 1; }
grep -q "^wind: wood: [0-9]* shape keys \['static', 'gust', 'sway_12_sin'.*action wind" "$out/wind.log" || {
  grep "^wind:" "$out/wind.log"; echo "blender_wind: unexpected shape keys"; exit 1; }
"$sprig" mesh species/abop_1_24a.yaml --steps 3 --lod none --wind 0 -o "$out/still.glb" >/dev/null
if blender -b --factory-startup --python scripts/blender-wind.py -- "$out/still.glb" >"$out/still.log" 2>&1; then
  echo "blender_wind: a tree without wind came in with shape keys"; exit 1
fi
grep -q "^wind: no part has shape keys" "$out/still.log"
echo "blender_wind: ok"
