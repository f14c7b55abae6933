#!/usr/bin/env bash
# `sprig animate` on a solid with operations, end to end (registered with ctest as
# `cli_animate_solid`): a clay-on-bronze ball with three operations (polish, dirt, polish).
#   1. without --stages it plays stages 0..3: exactly 4 frames, and frame k is byte for byte
#      the image of `sprig render --stage k` (the model after k operations);
#   2. `--stages 1..2` gives exactly the 2 frames of stages 1 and 2, the same bytes;
#   3. `--stages 2..9` is clamped to the list: stages 2 and 3;
#   4. the stages differ (each operation changes the picture), so the checks can fail.
# Usage: tests/cli/animate_solid_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"

cat >"$WORK/ball.yaml" <<'YAML'
kind: solid
solid:
  grid: {cell: 0.08}
  volume:
    distance_field: {sphere: {radius: 0.5}}
    layers:
      - interior_layer: {material: fired_clay, thickness: 0.12}
      - interior_layer: {material: bronze, thickness: fill}
  operations:
    - polish: {position: [0.45, 0.1, 0.2], size: 0.3, affects: [fired_clay], shiny: shiny_bronze, shines: [bronze]}
    - dirt: {color: "#303030"}
    - polish: {position: [-0.2, 0.45, 0.2], size: 0.3, affects: [fired_clay]}
render: {width: 48, height: 40, samples: 1}
YAML

frames() { find "$1" -name 'frame_*.png' | wc -l; }

# --- 1. the whole list -------------------------------------------------------------------
sprig animate "$WORK/ball.yaml" -o "$WORK/all" || fail "animate failed"
[ "$(frames "$WORK/all")" -eq 4 ] || fail "expected 4 frames (stages 0..3), got $(frames "$WORK/all")"
for k in 0 1 2 3; do
  sprig render "$WORK/ball.yaml" --stage "$k" -o "$WORK/stage$k.png" || fail "render --stage $k failed"
  cmp -s "$WORK/all/frame_0000$k.png" "$WORK/stage$k.png" || fail "frame $k differs from render --stage $k"
done

# --- 2. --stages 1..2 --------------------------------------------------------------------
sprig animate "$WORK/ball.yaml" -o "$WORK/part" --stages 1..2 || fail "animate --stages 1..2 failed"
[ "$(frames "$WORK/part")" -eq 2 ] || fail "--stages 1..2: expected 2 frames, got $(frames "$WORK/part")"
cmp -s "$WORK/part/frame_00000.png" "$WORK/stage1.png" || fail "--stages 1..2: first frame is not stage 1"
cmp -s "$WORK/part/frame_00001.png" "$WORK/stage2.png" || fail "--stages 1..2: second frame is not stage 2"

# --- 3. clamped ----------------------------------------------------------------------------
sprig animate "$WORK/ball.yaml" -o "$WORK/tail" --stages 2..9 || fail "animate --stages 2..9 failed"
[ "$(frames "$WORK/tail")" -eq 2 ] || fail "--stages 2..9: expected 2 frames (clamped to 2..3), got $(frames "$WORK/tail")"
cmp -s "$WORK/tail/frame_00001.png" "$WORK/stage3.png" || fail "--stages 2..9: last frame is not stage 3"

# --- 4. every operation shows ---------------------------------------------------------------
for k in 1 2 3; do
  cmp -s "$WORK/stage$((k - 1)).png" "$WORK/stage$k.png" && fail "stages $((k - 1)) and $k render the same picture"
done
echo "animate on a solid: 4 frames, --stages 1..2 and 2..9 give 2 each, every frame equals its render --stage"
