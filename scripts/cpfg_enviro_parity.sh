#!/usr/bin/env bash
# cpfg's environmental programs: runs vlab's open L-system objects (`cpfg ... -e FILE.e`)
# with the real cpfg and with `sprig derive -e`, and compares the strings with the cpfg
# peer's compare.py (docs/GRAMMAR.md, "Environmental programs").
#
# Usage: bash scripts/cpfg_enviro_parity.sh VLAB_DIR [FILTER]
#        bash scripts/cpfg_enviro_parity.sh --fixtures VLAB_DIR     (remakes tests/assets/cpfg/enviro/*/cpfg.str)
#   VLAB_DIR  a vlab checkout whose cpfg is built (VLAB_DIR/.binaries/bin/cpfg, as the peer's
#             run.sh leaves it); the ENVIRO programs these objects need (honda81, chiba,
#             clover, ecosystem) are built here with qmake and make if missing, and the
#             CelticKnot object's obcheck against vlab's libcomm.
#   FILTER    a regular expression: only the objects whose id matches
# Env: SPRIG     the sprig binary (default build/sprig of this checkout; its folder also holds
#                sprig_enviro_test)
#      COMPARE   compare.py (default /work/shared/peers/cpfg/compare.py)
#      WORK      work folder (default /tmp/cpfg_enviro_parity)
#      MAX_STEPS most steps compared (default 30): the object's animate file's last frame (or
#                its derivation length when larger), at most this
#      MAX_BYTES largest cpfg string compared (default 1000000): the last step under it
#      TIMEOUT   seconds per program run (default 120)
# Prints a markdown table: identical / differs / sprig refuses / cpfg refuses, one row per object.
set -uo pipefail
HERE="$(cd "$(dirname "$0")/.." && pwd)"
FIXTURES=0
if [ "${1:-}" = "--fixtures" ]; then FIXTURES=1; shift; fi
VLAB="$(cd "${1:?usage: cpfg_enviro_parity.sh [--fixtures] VLAB_DIR [FILTER]}" && pwd)"
FILTER="${2:-.}"
SPRIG="${SPRIG:-$HERE/build/sprig}"
COMPARE="${COMPARE:-/work/shared/peers/cpfg/compare.py}"
WORK="${WORK:-/tmp/cpfg_enviro_parity}"
MAX_STEPS="${MAX_STEPS:-30}"
MAX_BYTES="${MAX_BYTES:-1000000}"
TIMEOUT="${TIMEOUT:-120}"
BIN="$VLAB/.binaries/bin"
[ -x "$BIN/cpfg" ] || { echo "no cpfg at $BIN/cpfg: build it first (../shared/peers/cpfg/run.sh)" >&2; exit 2; }
[ -x "$SPRIG" ] || { echo "no sprig at $SPRIG" >&2; exit 2; }
export PATH="$BIN:$(dirname "$SPRIG"):$PATH"
mkdir -p "$WORK"
head -c 768 /dev/zero > "$WORK/dummy.map"   # cpfg -g wants a colour map; it does not affect the string

if [ $FIXTURES = 1 ]; then
  for d in "$HERE"/tests/assets/cpfg/enviro/*/; do
    e=$(cd "$d" && ls *.e)
    rm -rf "$WORK/fixture" && cp -r "$d" "$WORK/fixture"
    (cd "$WORK/fixture" && timeout "$TIMEOUT" cpfg -g -m "$WORK/dummy.map" -e "$e" -str cpfg.str plant.l plant.v >/dev/null 2>&1) &&
      cp "$WORK/fixture/cpfg.str" "$d/cpfg.str" && echo "remade $d/cpfg.str"
  done
  exit 0
fi

# ---------------------------------------------------------------- vlab's programs
for p in honda81 chiba clover ecosystem; do
  [ -x "$BIN/$p" ] && continue
  echo "building $p" >&2
  (cd "$VLAB/ENVIRO/$p" && qmake >/dev/null && nice -n 10 make -j2 >"$WORK/build_$p.log" 2>&1) ||
    { echo "build of $p failed: see $WORK/build_$p.log" >&2; exit 1; }
done

# ---------------------------------------------------------------- the objects
OOFS="$VLAB/oofs/ext"
OBJECTS=(
  10-manuals/ext/20-EnviroPgms/ext/CPFG-CelticKnot
  10-manuals/ext/20-EnviroPgms/ext/CPFG-Clover
  10-manuals/ext/20-EnviroPgms/ext/CPFG-Ecosystem
  10-manuals/ext/20-EnviroPgms/ext/CPFG-Sierpinski
  11-CPFG/ext/07-Open/ext/01-ulam-collide
  11-CPFG/ext/07-Open/ext/02-ulam3D-collide
  11-CPFG/ext/07-Open/ext/03-sierpinski-collide
  11-CPFG/ext/07-Open/ext/04-sierpinski-random
  11-CPFG/ext/07-Open/ext/06-canalization
  11-CPFG/ext/07-Open/ext/07-canalization-output
  11-CPFG/ext/07-Open/ext/08-canalization-file
  11-CPFG/ext/07-Open/ext/09-two-tiers
  11-CPFG/ext/07-Open/ext/10-light-three-spheres
  11-CPFG/ext/07-Open/ext/11-light-sierp-tetra
  11-CPFG/ext/07-Open/ext/12-two-trees
  11-CPFG/ext/07-Open/ext/13-clover
)
RESULTS="$WORK/results.tsv"
: > "$RESULTS"
first_line() { grep -a -m1 -i -E 'error|cannot|not supported' "$1" | tr '\t' ' ' | cut -c1-220 || true; }

run_object() {
  local obj="$1" id="${1//ext\//}"
  local W="$WORK/cases/$(echo "$id" | tr '/' '_')"
  rm -rf "$W" && mkdir -p "$W" && cp -r "$OOFS/$obj/." "$W/" && mkdir -p "$W/out"
  # the cpfg line of the object's specifications: NAME.l, VIEW.v, FILE.e, ANIM.a
  local line; line=$(grep -m1 -E '^\s*cpfg ' "$W/specifications")
  local lfile vfile efile afile
  lfile=$(echo "$line" | grep -o -E '[^ ]+\.l( |$)' | head -1 | tr -d ' ')
  vfile=$(echo "$line" | grep -o -E '[^ ]+\.v( |$)' | head -1 | tr -d ' ')
  efile=$(echo "$line" | grep -o -E '\-e [^ ]+' | cut -d' ' -f2)
  afile=$(echo "$line" | grep -o -E '[^ ]+\.a( |$)' | head -1 | tr -d ' ')
  [ "$vfile" != "${lfile%.l}.v" ] && cp "$W/$vfile" "$W/${lfile%.l}.v"   # Sprig reads NAME.v beside NAME.l
  if [ -f "$W/obcheck.c" ]; then   # CelticKnot ships its program's source and a macOS libcomm.a
    (cd "$W" && gcc -O2 -o obcheck obcheck.c "$VLAB/libs/comm/message.c" -I"$VLAB/libs/comm" -L"$VLAB/.libraries" -lcomm -lm \
      >"$W/out/obcheck_build.log" 2>&1) || { printf '%s\t-\tcpfg refuses\tobcheck does not build\n' "$id" >> "$RESULTS"; return; }
  fi
  # steps: the animate file's last frame or the derivation length, at most MAX_STEPS
  local n last
  n=$(cd "$W" && timeout 30 cpfg -V -g -m "$WORK/dummy.map" "$lfile" "$vfile" 2>&1 | grep -a -m1 -o 'Derivation length is -\?[0-9]*' | head -1 | grep -o -- '-\?[0-9]*$')
  last=$(grep -o -E "last frame: *-?[0-9]+" "$W/$afile" 2>/dev/null | head -1 | grep -o -E -- "-?[0-9]+$")
  [ -n "$n" ] || n=1
  [ -n "$last" ] || last=0
  [ "$last" -lt "$n" ] && last=$n
  [ "$last" -gt "$MAX_STEPS" ] && last=$MAX_STEPS
  [ "$last" -lt 1 ] && last=1
  printf 'first frame: 0\nlast frame: %d\nstep: 1\n' "$last" > "$W/out/steps.a"
  (cd "$W" && timeout "$TIMEOUT" nice -n 10 cpfg -g -a -m "$WORK/dummy.map" -e "$efile" -str "$W/out/s%03d.str" "$lfile" "$vfile" "$W/out/steps.a" \
    > "$W/out/cpfg.log" 2>&1)
  local rc=$?
  local k; k=$(python3 "$COMPARE" pick "$W/out" $((last + 1)) "$MAX_BYTES" $rc)
  if [ "$k" -lt 1 ]; then
    printf '%s\t-\tcpfg refuses\trc %s: %s\n' "$id" "$rc" "$(first_line "$W/out/cpfg.log")" >> "$RESULTS"; return
  fi
  cp "$(printf '%s/out/s%03d.str' "$W" "$k")" "$W/out/cpfg.str"
  (cd "$W" && timeout "$TIMEOUT" nice -n 10 "$SPRIG" -q derive "$lfile" --print --steps "$k" -e "$efile" \
    > "$W/out/sprig.str" 2> "$W/out/sprig.log")
  if [ ! -s "$W/out/sprig.str" ]; then
    printf '%s\t%s\tsprig refuses\t%s\n' "$id" "$k" "$(first_line "$W/out/sprig.log" | sed "s|$W/||g")" >> "$RESULTS"; return
  fi
  printf '%s\t%s\t%s\n' "$id" "$k" "$(python3 "$COMPARE" diff "$W/out/cpfg.str" "$W/out/sprig.str")" >> "$RESULTS"
}

for obj in "${OBJECTS[@]}"; do
  [[ "$obj" =~ $FILTER ]] || continue
  echo "running $obj" >&2
  run_object "$obj"
done
python3 "$COMPARE" table "$RESULTS" | tee "$WORK/table.md"
echo "(per-object files: $WORK/cases/*/out/)" >&2
