#!/usr/bin/env bash
# Runs every case of tests/bad_inputs/cases.txt against the sprig binary given as $1.
# Run from the repository root (ctest does). For each case it checks:
#   - the exit code is exactly the expected one (so no crash, no signal),
#   - stderr holds the expected line exactly (`file:line:col: error: ...`),
#   - nothing was written: the case's output folder $OUT is empty afterwards and no
#     temporary (.sprig-tmp-*) file is left beside the inputs.
# A case is a block of lines `name:`, `args:` (split on spaces; $OUT is a fresh empty
# folder), `exit:`, one or more `expect:` lines and optionally `maxlines: N` (stderr holds
# at most N lines and N*200 bytes: a long line or a binary file is never echoed whole),
# `setup: SHELL COMMAND` (run by bash from the repository root before the case, with $IN a
# fresh folder for inputs it makes: FIFOs, many generated files; $SPRIG is the binary; $IN may appear in `args:`
# and `expect:`) and `cd: DIR` (sprig runs in DIR, relative to the repository root);
# blocks are separated by blank lines.
set -u
SPRIG=${1:?usage: run.sh PATH/TO/sprig}
SPRIG=$(cd "$(dirname "$SPRIG")" && pwd)/$(basename "$SPRIG")  # absolute: `cd:` cases run elsewhere
HERE=$(cd "$(dirname "$0")" && pwd)
CASES="$HERE/cases.txt"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

pass=0
fail=0
name="" args="" code="" expects=() maxlines="" setup="" dir=""
ROOT=$(pwd)

run_case() {
  [ -z "$name" ] && return
  local out="$WORK/$name"
  local in="$WORK/$name.in"
  mkdir -p "$out" "$in"
  local expanded=${args//\$OUT/$out}
  expanded=${expanded//\$IN/$in}
  local stderr_file="$WORK/$name.stderr"
  if [ -n "$setup" ] && ! IN="$in" SPRIG="$SPRIG" bash -c "$setup"; then
    echo "FAIL $name: setup failed: $setup"; fail=$((fail + 1)); name="" args="" code="" expects=() maxlines="" setup="" dir=""; return
  fi
  # shellcheck disable=SC2086
  (cd "$ROOT/${dir:-.}" && timeout 120 "$SPRIG" --quiet $expanded) >"$WORK/$name.stdout" 2>"$stderr_file"
  local rc=$?
  local ok=1 why=""
  if [ "$rc" != "$code" ]; then ok=0; why="exit code $rc, expected $code"; fi
  for e in "${expects[@]}"; do
    e=${e//\$OUT/$out}
    e=${e//\$IN/$in}
    if ! grep -qxF -- "$e" "$stderr_file"; then ok=0; why="$why${why:+; }missing line: $e"; fi
  done
  if [ -n "$maxlines" ]; then
    local lines bytes
    lines=$(wc -l <"$stderr_file") bytes=$(wc -c <"$stderr_file")
    if [ "$lines" -gt "$maxlines" ] || [ "$bytes" -gt $((maxlines * 200)) ]; then
      ok=0; why="$why${why:+; }stderr has $lines lines, $bytes bytes (at most $maxlines lines)"
    fi
  fi
  if [ -n "$(find "$out" -mindepth 1 -print -quit)" ]; then
    ok=0; why="$why${why:+; }left files: $(find "$out" -mindepth 1 | tr '\n' ' ')"
  fi
  if [ -n "$(find "$HERE" -name '.sprig-tmp-*' -print -quit)" ]; then
    ok=0; why="$why${why:+; }left temporaries beside the inputs"
  fi
  if [ $ok = 1 ]; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL $name: $why"
    echo "  command: sprig --quiet $expanded"
    sed 's/^/  stderr: /' "$stderr_file"
  fi
  name="" args="" code="" expects=() maxlines="" setup="" dir=""
}

while IFS= read -r line || [ -n "$line" ]; do
  case "$line" in
    "#"*) ;;
    "") run_case ;;
    name:\ *) name=${line#name: } ;;
    args:\ *) args=${line#args: } ;;
    exit:\ *) code=${line#exit: } ;;
    expect:\ *) expects+=("${line#expect: }") ;;
    maxlines:\ *) maxlines=${line#maxlines: } ;;
    setup:\ *) setup=${line#setup: } ;;
    cd:\ *) dir=${line#cd: } ;;
    *) echo "cases.txt: cannot read line: $line"; exit 2 ;;
  esac
done <"$CASES"
run_case

echo "bad_inputs: $pass passed, $fail failed"
[ $fail = 0 ]
