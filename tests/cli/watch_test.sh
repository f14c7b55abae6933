#!/usr/bin/env bash
# Watch mode (registered with ctest as `cli_watch`):
#   1. `sprig preview --watch` (inotify) renders, re-renders when the species file is saved
#      in place and when it is saved the way editors do (a new file renamed over it), and
#      the picture changes each time;
#   2. a bad edit prints its file:line:col error, leaves the last good picture byte for byte
#      and the watch goes on; repairing the file renders again;
#   3. `sprig render --watch --watch-poll` (the polling fallback) re-renders when a file the
#      species references (its grammar) is saved, and only then;
#   4. --watch-max-renders without --watch is a usage error.
# Usage: tests/cli/watch_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
SPRIG=$(realpath "$1")
SRC=$(pwd)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-watch-test-XXXXXX")
pid=""
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; [ -f "$WORK/lib/log" ] && cat "$WORK/lib/log" >&2; exit 1; }

mkdir -p "$WORK/lib/species" "$WORK/lib/grammars"
cp "$SRC/grammars/abop_1_24a.lsys" "$WORK/lib/grammars/"
cd "$WORK/lib"
species() {  # species/s.yaml with $1 derivation steps
  printf 'name: watched\nkind: tree\ngrammar: ../grammars/abop_1_24a.lsys\nsteps: %s\nrender: {width: 96, height: 96, samples: 1}\n' "$1"
}
species 2 > species/s.yaml

# Waits (at most 60 s) until the log has $1 lines matching $2.
wait_for() {
  for _ in $(seq 1 600); do
    [ "$(grep -c -- "$2" log || true)" -ge "$1" ] && return 0
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  [ "$(grep -c -- "$2" log || true)" -ge "$1" ] || fail "timed out waiting for $1 x '$2'"
}
sum() { md5sum "$1" | cut -d' ' -f1; }

# --- 1 and 2: preview, inotify -----------------------------------------------------------
"$SPRIG" --root . preview species/s.yaml -o out.png --watch --watch-max-renders 5 2> log &
pid=$!
wait_for 1 "render 1 wrote out.png"
grep -q "(inotify)" log || fail "inotify was not used"
a=$(sum out.png)
sleep 0.2
species 3 > species/s.yaml                      # saved in place
wait_for 1 "render 2 wrote out.png"
b=$(sum out.png)
[ "$a" != "$b" ] || fail "the picture did not change after the species was saved"
sleep 0.2
species 4 > species/s.yaml.tmp && mv species/s.yaml.tmp species/s.yaml   # saved by rename
wait_for 1 "render 3 wrote out.png"
c=$(sum out.png)
[ "$c" != "$b" ] || fail "the picture did not change after a save by rename"
sleep 0.2
species many > species/s.yaml                   # a bad edit
wait_for 1 "render 4 failed"
grep -qxF "species/s.yaml:4:8: error: 'steps' must be an integer, got 'many'" log || fail "no file:line:col error for the bad edit"
[ "$(sum out.png)" = "$c" ] || fail "a bad edit changed the last good picture"
sleep 0.2
species 2 > species/s.yaml                      # repaired: back to the first picture
wait_for 1 "render 5 wrote out.png"
rc=0; wait "$pid" || rc=$?
pid=""
[ "$rc" -eq 0 ] || fail "watch ended with exit $rc after a good last render"
[ "$(sum out.png)" = "$a" ] || fail "the repaired species should give the first picture again"
[ -z "$(find . -name '.sprig-tmp-*')" ] || fail "temporaries left"

# --- 3: render, polling, a referenced file -------------------------------------------------
"$SPRIG" --root . render species/s.yaml -o r.png --mode skeleton --watch --watch-poll --watch-max-renders 2 2> log &
pid=$!
wait_for 1 "render 1 wrote r.png"
grep -q "(polling)" log || fail "--watch-poll did not poll"
a=$(sum r.png)
touch species/s.yaml                            # same bytes: not a change
sleep 1
[ "$(grep -c "render 2" log || true)" -eq 0 ] || fail "a touch without a change re-rendered"
sed -i "s/^angle: 25.7/angle: 60/" grammars/abop_1_24a.lsys
grep -q "^angle: 60" grammars/abop_1_24a.lsys || fail "test set-up: the grammar edit did not apply"
wait_for 1 "render 2 wrote r.png"
wait "$pid"
pid=""
[ "$(sum r.png)" != "$a" ] || fail "the picture did not change after the grammar was saved"

# --- 4: flags ---------------------------------------------------------------------------
rc=0; "$SPRIG" --root . preview species/s.yaml -o x.png --watch-max-renders 2 2> log || rc=$?
[ "$rc" -eq 2 ] || fail "--watch-max-renders without --watch: exit $rc, expected 2"
grep -qxF "sprig: error: --watch-max-renders and --watch-poll need --watch" log || fail "no usage message"
[ ! -e x.png ] || fail "a usage error wrote a picture"
echo "watch: ok"
