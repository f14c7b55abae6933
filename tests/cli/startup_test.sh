#!/usr/bin/env bash
# Start-up (issue 19; registered with ctest as `cli_startup`):
#   1. the sprig binary links neither OpenImageIO nor OpenVDB (backends/backends.h);
#   2. `--version`, `check` and `derive` of a grammar load neither, nor libsprig_backends.so;
#   3. a command that writes an image loads libsprig_backends.so from beside the binary and
#      writes the image;
#   4. a sprig binary without libsprig_backends.so beside it still checks and derives, and
#      a command that needs an image fails with exit 3, a message naming the library, and
#      no file.
# Usage: tests/cli/startup_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"
heavy='lib(OpenImageIO|openvdb)[^/]*\.so'
# The shared objects a run of sprig maps ("file=NAME [0];  needed by ..." / dlopen lines).
loaded() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -oE 'file=[^ ]+' | sort -u || true; }

# --- 1. linked libraries ----------------------------------------------------------------
! ldd "$SPRIG" | grep -E "$heavy" || fail "sprig links OpenImageIO or OpenVDB"

# --- 2. commands that write no image --------------------------------------------------------
for args in "--version" "check grammars/abop_2_6.lsys" "derive grammars/abop_2_6.lsys --steps 8"; do
  # shellcheck disable=SC2086
  libs=$(loaded "$SPRIG" --quiet $args)
  [ -n "$libs" ] || fail "LD_DEBUG reported no libraries for 'sprig $args'"
  ! grep -E "$heavy|libsprig_backends" <<<"$libs" || fail "'sprig $args' loaded the libraries above"
done

# --- 3. a command that writes an image --------------------------------------------------------
libs=$(loaded "$SPRIG" --quiet preview grammars/abop_2_6.lsys --width 32 --height 32 -o "$WORK/p.png")
[ -s "$WORK/p.png" ] || fail "preview wrote no image"
grep -q "libsprig_backends.so" <<<"$libs" || fail "preview did not load libsprig_backends.so: $libs"

# --- 4. without the library -------------------------------------------------------------------
mkdir "$WORK/alone"
cp "$SPRIG" "$WORK/alone/sprig"
"$WORK/alone/sprig" --quiet check grammars/abop_2_6.lsys || fail "check needs libsprig_backends.so"
"$WORK/alone/sprig" --quiet derive grammars/abop_2_6.lsys --steps 8 >/dev/null || fail "derive needs libsprig_backends.so"
set +e
err=$("$WORK/alone/sprig" --quiet preview grammars/abop_2_6.lsys --width 32 --height 32 -o "$WORK/q.png" 2>&1)
code=$?
set -e
[ $code = 3 ] || fail "preview without libsprig_backends.so: exit $code, expected 3 ($err)"
grep -q "cannot load libsprig_backends.so" <<<"$err" || fail "preview without libsprig_backends.so: $err"
[ ! -e "$WORK/q.png" ] || fail "preview without libsprig_backends.so left a file"
ls -A "$WORK" | grep -q sprig-tmp && fail "a temporary file was left behind"
echo "start-up: sprig loads OpenImageIO and OpenVDB only for commands that use them"
