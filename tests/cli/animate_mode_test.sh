#!/usr/bin/env bash
# `sprig animate --mode` (registered with ctest as `cli_animate_mode`): for each mode
# (exact, mesh, skeleton) the frame of a one-stage animation of a small tree is byte for
# byte `sprig render --mode` of the same stage and size, `--at` gives those bytes too, and
# the three modes give three different pictures (so the comparison can fail). A species
# with render.pair animates alone and prints a note saying so.
# Usage: tests/cli/animate_mode_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"
SPECIES=species/fig_tree_11_branching.yaml
size=(--width 48 --height 40)
for mode in exact mesh skeleton; do
  sprig animate "$SPECIES" -o "$WORK/$mode" --mode "$mode" --stages 0..0 --frames-per-stage 1 "${size[@]}" --samples 1
  n=$(find "$WORK/$mode" -name 'frame_*.png' | wc -l)
  [ "$n" -eq 1 ] || fail "--mode $mode: expected one frame, got $n"
  sprig render "$SPECIES" -o "$WORK/$mode.png" --mode "$mode" --stage 0 "${size[@]}" --spp 1
  cmp -s "$WORK/$mode/frame_00000.png" "$WORK/$mode.png" || fail "--mode $mode: the frame differs from sprig render"
  sprig animate "$SPECIES" -o "$WORK/${mode}_at.png" --mode "$mode" --at 0 "${size[@]}" --samples 1
  cmp -s "$WORK/${mode}_at.png" "$WORK/$mode.png" || fail "--mode $mode --at 0 differs from sprig render"
done
! cmp -s "$WORK/exact.png" "$WORK/skeleton.png" || fail "exact and skeleton frames are the same picture"
! cmp -s "$WORK/exact.png" "$WORK/mesh.png" || fail "exact and mesh frames are the same picture"
# A paired species animates alone, and says so.
"$SPRIG" animate species/fig_tree_12_pcm_no_offset.yaml -o "$WORK/paired.png" --mode skeleton --at 0 "${size[@]}" 2>"$WORK/paired.err" >/dev/null
grep -q "note: render.pair ('fig_tree_12_pcm_offset.yaml') pairs the picture only" "$WORK/paired.err" ||
  fail "a paired species' animation does not say it shows the species alone: $(cat "$WORK/paired.err")"
# A bad mode is a usage error.
set +e
"$SPRIG" --quiet animate "$SPECIES" -o "$WORK/bad" --mode wire 2>"$WORK/err"
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "--mode wire: exit $rc, expected 2"
grep -q "mode" "$WORK/err" || fail "--mode wire: message does not name the flag: $(cat "$WORK/err")"
echo "ok"
