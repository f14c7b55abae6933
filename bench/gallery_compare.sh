#!/usr/bin/env bash
# Do the exact renderer's fast paths change the pictures? Renders the whole draft gallery
# twice with the same binary: as shipped (each surface cell traces its pruned tape), and with
# `sprig --full-tape` (every cell walks the whole BlobTree tape: the reference the pruned
# tapes are checked against). Then compares every PNG pair with OpenImageIO's idiff and every
# GIF pair byte for byte, and prints the images that differ (pixels over 0, the largest
# difference in 1/255) and a summary.
#
#   bash bench/gallery_compare.sh [SPRIG] [OUT]   (defaults: build/sprig, /tmp/sprig-gallery-compare)
#
# Takes about twice a draft gallery's time (`make gallery`). Set SKIP_RENDER=1 to compare
# folders already rendered.
set -euo pipefail
shopt -s nullglob
repo=$(cd "$(dirname "$0")/.." && pwd)
sprig=$(realpath "${1:-$repo/build/sprig}")
out=${2:-/tmp/sprig-gallery-compare}
[[ -x $sprig ]] || { echo "gallery_compare.sh: no sprig binary at $sprig (build first)" >&2; exit 1; }
command -v idiff >/dev/null || { echo "gallery_compare.sh: idiff (openimageio-tools) is not installed" >&2; exit 1; }
mkdir -p "$out"
if [[ ${SKIP_RENDER:-0} != 1 ]]; then
  (cd "$repo" && /usr/bin/time -f "pruned tapes: %e s wall, %U s user" "$sprig" -q gallery -o "$out/pruned")
  (cd "$repo" && /usr/bin/time -f "full tape: %e s wall, %U s user" "$sprig" -q --full-tape gallery -o "$out/full")
fi

same=0 differ=0 pixels=0 worst=0 gifs=0 gifsDiffer=0
for a in "$out"/pruned/*.png; do
  name=$(basename "$a")
  b="$out/full/$name"
  [[ -f $b ]] || { echo "$name: missing from the full-tape gallery"; differ=$((differ + 1)); continue; }
  if cmp -s "$a" "$b"; then same=$((same + 1)); continue; fi
  report=$(idiff -fail 0 -warn 0 -abs "$a" "$b" 2>&1 || true)
  n=$(awk '/pixels .* over 0/ { print $1; exit }' <<<"$report")
  share=$(awk '/pixels .* over 0/ { print $3; exit }' <<<"$report")
  maxErr=$(awk -F'= ' '/Max error/ { split($2, v, " "); print v[1]; exit }' <<<"$report")
  if [[ -z $n || $n == 0 ]]; then same=$((same + 1)); continue; fi
  max255=$(awk -v m="$maxErr" 'BEGIN { printf "%d", m * 255 + 0.5 }')
  echo "$name: $n pixels $share differ, at most $max255/255"
  differ=$((differ + 1))
  pixels=$((pixels + n))
  ((max255 > worst)) && worst=$max255
done
for a in "$out"/pruned/*.gif; do
  gifs=$((gifs + 1))
  cmp -s "$a" "$out/full/$(basename "$a")" || { echo "$(basename "$a"): animation bytes differ"; gifsDiffer=$((gifsDiffer + 1)); }
done
echo "PNG images: $((same + differ)) compared, $same identical in every pixel, $differ differ" \
     "($pixels pixels in all, at most $worst/255); GIF animations: $gifs compared, $gifsDiffer differ"
