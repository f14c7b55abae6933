#!/usr/bin/env bash
# The README against the repository (registered with ctest):
#   readme_links     every relative link and #anchor of README.md and docs/*.md resolves,
#                    docs/FIGURES.md has a row for every figure species,
#                    and the tutorial's file blocks equal docs/tutorial/* (no binary run);
#   readme_tutorial  the tutorial's commands as the README writes them, in a scratch
#                    folder holding a copy of docs/tutorial/ and `build` linked to the build
#                    folder; each block's output against the README's expected lines, then
#                    the files they wrote: PNG and GIF sizes, the glb's parts, the .blend
#                    (when blender is installed). Labelled heavy (about a minute).
# Usage: tests/docs/readme_test.sh links|tutorial BUILD_DIR   (run from the repository root)
set -euo pipefail
mode=${1:?usage: $0 links|tutorial BUILD_DIR}
BUILD=$(realpath "${2:?usage: $0 links|tutorial BUILD_DIR}")
ROOT=$(pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }
py() { /usr/bin/python3 "$ROOT/tests/docs/readme.py" "$@"; }

if [ "$mode" = links ]; then
  py links "$ROOT" README.md docs/*.md
  py files "$ROOT" README.md
  py figures "$ROOT" docs/FIGURES.md
  echo "readme_links: ok"
  exit 0
fi
[ "$mode" = tutorial ] || fail "unknown mode '$mode'"

WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-readme-XXXXXX")
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/docs"
cp -r docs/tutorial "$WORK/docs/tutorial"
ln -s "$BUILD" "$WORK/build"
blender=()
command -v blender >/dev/null && blender=(--blender)
py run "$ROOT" README.md "$WORK" "${blender[@]}"

# The files, as the README describes them.
/usr/bin/python3 - "$WORK/out" "${#blender[@]}" <<'PY'
import json, os, struct, sys
out, with_blender = sys.argv[1], sys.argv[2] == "1"
def fail(msg):
    sys.exit("FAIL: " + msg)
def png_size(name):
    b = open(os.path.join(out, name), "rb").read(24)
    if b[:8] != b"\x89PNG\r\n\x1a\n": fail(f"{name} is not a PNG")
    return struct.unpack(">II", b[16:24])
def gif(name):
    b = open(os.path.join(out, name), "rb").read()
    if b[:6] != b"GIF89a": fail(f"{name} is not a GIF89a")
    w, h = struct.unpack("<HH", b[6:10])
    # count image descriptors by walking the blocks
    i = 13 + (3 << ((b[10] & 7) + 1) if b[10] & 0x80 else 0)
    frames = 0
    while i < len(b) and b[i] != 0x3B:
        if b[i] == 0x21:                      # extension: label, then sub-blocks
            i += 2
            while b[i]: i += b[i] + 1
            i += 1
        elif b[i] == 0x2C:                    # image: descriptor, local table, LZW sub-blocks
            flags = b[i + 9]
            i += 10 + (3 << ((flags & 7) + 1) if flags & 0x80 else 0) + 1
            while b[i]: i += b[i] + 1
            i += 1
            frames += 1
        else:
            fail(f"{name}: unexpected GIF block 0x{b[i]:02x} at {i}")
    return (w, h), frames
for name, size in [("sapling-preview.png", (640, 640)), ("sapling-young.png", (640, 640)),
                   ("sapling.png", (480, 480)), ("sapling_narrow.png", (320, 320))]:
    if png_size(name) != size: fail(f"{name}: {png_size(name)}, the README says {size}")
for name, frames in [("growing.gif", 15), ("windy.gif", 12)]:
    size, n = gif(name)
    if size != (200, 200) or n != frames: fail(f"{name}: {size} with {n} frames, the README says 200x200 with {frames}")
b = open(os.path.join(out, "sapling.glb"), "rb").read()
if b[:4] != b"glTF": fail("sapling.glb is not a glb")
length = struct.unpack("<I", b[12:16])[0]
doc = json.loads(b[20:20 + length])
names = sorted(n.get("name", "") for n in doc["nodes"] if "mesh" in n)
if names != ["leaves", "wood"]: fail(f"sapling.glb's parts are {names}, the README says wood and leaves")
if not doc.get("images"): fail("sapling.glb has no texture image (the wood's bark)")
if with_blender:
    blend = open(os.path.join(out, "sapling.blend"), "rb").read(7)
    if blend != b"BLENDER": fail("sapling.blend is not a Blender file")
print("readme_tutorial: ok" + ("" if with_blender else " (blender not installed: step 7 not run)"))
PY
