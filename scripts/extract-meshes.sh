#!/usr/bin/env bash
# Extracts the free meshes Sprig's organisms use from CGAL's demo data into OUTDIR.
#
#   scripts/extract-meshes.sh OUTDIR
#
# Source: /usr/share/doc/libcgal-demo/data.tar.gz (Debian package libcgal-demo, installed by
# scripts/install-deps.sh). Licences: docs/MESHES.md. Idempotent and atomic: the files are
# extracted into a temporary folder beside OUTDIR, checked against SHA256SUMS, and renamed
# into place (the whole folder when OUTDIR is new, file by file otherwise, SHA256SUMS last,
# so an interrupted run is redone by the next). Prints nothing when OUTDIR is up to date.
set -euo pipefail

if [ $# -ne 1 ] || [ -z "$1" ]; then
  echo "usage: $0 OUTDIR" >&2
  exit 2
fi
out=${1%/}
tarball=${SPRIG_CGAL_DATA:-/usr/share/doc/libcgal-demo/data.tar.gz}

# The files, as named in the tarball (CGAL 5.5, Debian 12).
files=(
  data/meshes/mannequin-devil.off
  data/meshes/head.off
  data/meshes/fandisk.off
  data/meshes/torus_quad.off
  data/meshes/sphere.off
  data/meshes/cactus.off
  data/meshes/mushroom.off
  data/images/skull_2.9.inr
)

if [ ! -r "$tarball" ]; then
  echo "$0: error: $tarball is missing: install libcgal-demo (scripts/install-deps.sh)" >&2
  exit 1
fi

# Up to date: every file present and matching the sums written when it was extracted.
if [ -f "$out/SHA256SUMS" ] && [ "$(wc -l < "$out/SHA256SUMS")" -eq ${#files[@]} ] &&
   (cd "$out" && sha256sum --check --quiet --status SHA256SUMS) 2>/dev/null; then
  exit 0
fi

parent=$(dirname -- "$out")
mkdir -p -- "$parent"
tmp=$(mktemp -d "$parent/.extract-meshes.XXXXXX")
trap 'rm -rf -- "$tmp"' EXIT
tar -xzf "$tarball" -C "$tmp" "${files[@]}"
names=()
for f in "${files[@]}"; do
  mv -- "$tmp/$f" "$tmp/${f##*/}"
  names+=("${f##*/}")
done
rm -rf -- "$tmp/data"
(cd "$tmp" && sha256sum -- "${names[@]}" > SHA256SUMS)

if [ ! -e "$out" ]; then
  mv -T -- "$tmp" "$out"
else
  for n in "${names[@]}"; do mv -f -- "$tmp/$n" "$out/$n"; done
  mv -f -- "$tmp/SHA256SUMS" "$out/SHA256SUMS"
fi
echo "extracted ${#names[@]} files from $tarball into $out"
