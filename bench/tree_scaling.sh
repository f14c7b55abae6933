#!/usr/bin/env bash
# Whole-process cost of an exact render as the tree grows (issue 19): ABOP figure 2.6a as a
# BlobTree tree (species/tree_abop_2_6.yaml) at 1,023, 4,095, 16,383 and 65,535 internodes,
# 384x384, 1 sample per pixel. Prints wall and CPU seconds, CPU milliseconds per 1,000
# internodes, and each size's per-internode cost as a ratio of the smallest's (the baseline
# of the same run): flat cost means ratios near 1.
#
#   bash bench/tree_scaling.sh [SPRIG] [STEPS...]      (default steps 10 12 14 16)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
sprig=$(realpath "${1:-$repo/build/sprig}")
shift || true
steps=("$@")
[[ ${#steps[@]} -gt 0 ]] || steps=(10 12 14 16)
[[ -x $sprig ]] || { echo "tree_scaling.sh: no sprig binary at $sprig (build first)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$repo/grammars/abop_2_6.lsys" "$tmp/"
base=""
printf '%6s %11s %8s %8s %14s %6s\n' steps internodes wall_s cpu_s cpu_ms_per_1k ratio
for n in "${steps[@]}"; do
  sed -e "s#^grammar: .*#grammar: abop_2_6.lsys#" -e "s/^steps: .*/steps: $n/" \
      -e "s/width: .*/width: 384/; s/height: .*/height: 384/; s/samples: .*/samples: 1/" \
      "$repo/species/tree_abop_2_6.yaml" > "$tmp/t$n.yaml"
  (cd "$tmp" && /usr/bin/time -f "%e %U %S" -o time "$sprig" render "t$n.yaml" -o "t$n.png" >/dev/null 2>log)
  read -r wall user sys < "$tmp/time"
  internodes=$(( (1 << n) - 1 ))
  per=$(awk -v u="$user" -v s="$sys" -v i="$internodes" 'BEGIN { printf "%.4f", 1e6 * (u + s) / i }')
  [[ -n $base ]] || base=$per
  awk -v n="$n" -v i="$internodes" -v w="$wall" -v u="$user" -v s="$sys" -v p="$per" -v b="$base" \
    'BEGIN { printf "%6d %11d %8.2f %8.2f %14.2f %6.2f\n", n, i, w, u + s, p, p / b }'
done
