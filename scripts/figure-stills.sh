#!/usr/bin/env bash
# Stills of every paper-figure species (species/fig_*, the blob figures and the Murex) at the
# gallery's draft size (0.16 megapixel, the species' aspect) and 4 samples, for
# scripts/contact-sheets.sh. Cheaper than a gallery: no strips, no animations.
#
#   bash scripts/figure-stills.sh [OUT_DIR] [SPRIG]      (from the repository root)
#
# OUT_DIR (default figures) receives NAME.png per species and times.txt.
set -euo pipefail
out=${1:-figures}
sprig=${2:-build/sprig}
mkdir -p "$out"
: > "$out/times.txt"
for f in species/fig_*.yaml species/blob_*.yaml species/shell_murex_cabritii.yaml; do
  n=$(basename "$f" .yaml)
  # The species' render.width/height (default 800 x 600), scaled to 0.16 megapixel.
  read -r w h < <(python3 - "$f" <<'PY'
import math, re, sys
text = open(sys.argv[1]).read()
m = re.search(r'^render:\s*\n((?:[ \t]+.*\n|\s*\n)*)', text, re.M)
block = m.group(1) if m else ''
w = re.search(r'^\s{2}width:\s*(\d+)', block, re.M)
h = re.search(r'^\s{2}height:\s*(\d+)', block, re.M)
w = int(w.group(1)) if w else 800
h = int(h.group(1)) if h else 600
s = min(1.0, math.sqrt(160000.0 / (w * h)))
print(max(16, int(w * s)), max(16, int(h * s)))
PY
  )
  start=$(date +%s%N)
  "$sprig" -q render "$f" -o "$out/$n.png" --width "$w" --height "$h" --spp 4 || { echo "figure-stills: $n failed" >&2; exit 1; }
  echo "$n $((($(date +%s%N) - start) / 1000000)) ms" >> "$out/times.txt"
done
echo "$out: $(ls "$out"/*.png | wc -l) stills"
