#!/usr/bin/env bash
# Contact sheets of the paper figures: one PNG per paper, every figure species' gallery still
# fitted into a labelled cell, in file-name (figure) order.
#
#   bash scripts/contact-sheets.sh [GALLERY_DIR] [OUT_DIR]
#
# GALLERY_DIR (default gallery/out) is a finished `sprig gallery` folder (or the folder of
# scripts/figure-stills.sh); OUT_DIR (default
# GALLERY_DIR/sheets) receives blobtree.png, shells.png, organisms.png and solids.png.
# Needs oiiotool (OpenImageIO's command-line tool, installed with the build dependencies).
set -euo pipefail

gallery=${1:-gallery/out}
out=${2:-$gallery/sheets}
cell=${CELL:-360x270}   # each still is fitted (aspect kept) into this cell
columns=${COLUMNS_PER_SHEET:-4}

command -v oiiotool >/dev/null || { echo "contact-sheets: error: oiiotool not found" >&2; exit 1; }
[ -d "$gallery" ] || { echo "contact-sheets: error: $gallery: no such gallery folder" >&2; exit 1; }
mkdir -p "$out"
# oiiotool finds no default font on Debian: name DejaVu Sans (fonts-dejavu-core) by path;
# without it the cells go unlabelled and the order is printed instead.
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf

cw=${cell%x*} ch=${cell#*x}
band=24   # the label's band above each picture

# cellArgs STILL: oiiotool arguments that leave STILL fitted into a grey cell (aspect kept,
# centred) under a band with its species name.
cellArgs() {
  local still=$1 label size w h fw fh
  label=$(basename "$still" .png)
  size=$(oiiotool --info "$still" | sed -n 's/.* : *\([0-9]*\) x *\([0-9]*\),.*/\1 \2/p')
  read -r w h <<<"$size"
  if ((w * ch > h * cw)); then fw=$cw fh=$(((h * cw + w / 2) / w)); else fh=$ch fw=$(((w * ch + h / 2) / h)); fi
  # --paste puts the next-to-top image (the still) onto the top one (the cell).
  cargs=("$still" --ch R,G,B --resize "${fw}x${fh}" --pattern constant:color=0.9,0.9,0.9 "${cw}x$((ch + band))" 3
         --paste "+$(((cw - fw) / 2))+$((band + (ch - fh) / 2))")
  if [ -f "$font" ]; then cargs+=(--text:x=6:y=18:size=15:color=0.05,0.05,0.05:font="$font" "$label"); fi
}

# sheet NAME GLOB...: the stills of the species whose names match a glob, in order.
sheet() {
  local name=$1; shift
  local args=() n=0 still
  for pattern in "$@"; do
    for still in "$gallery"/$pattern.png; do
      [ -f "$still" ] || continue
      case $still in *_stages.png) continue ;; esac
      cellArgs "$still"
      args+=("${cargs[@]}")
      n=$((n + 1))
      [ -f "$font" ] || echo "  $n: $(basename "$still" .png)"
    done
  done
  if [ "$n" -eq 0 ]; then echo "contact-sheets: no stills for $name in $gallery" >&2; return; fi
  local rows=$(((n + columns - 1) / columns))
  # Pad the last row with blank cells so --mosaic gets exactly columns x rows images.
  local blanks=$((rows * columns - n)) i
  for ((i = 0; i < blanks; i++)); do args+=(--pattern constant:color=1,1,1 "${cw}x$((ch + band))" 3); done
  oiiotool "${args[@]}" --mosaic:pad=6 "${columns}x${rows}" -o "$out/$name.png"
  echo "$out/$name.png: $n figures"
}

sheet blobtree 'blob_*' 'fig_tree_*'
sheet shells 'fig_shell_*' 'shell_murex_cabritii'
sheet organisms 'fig_org_*'
sheet solids 'fig_solid_*'
