#!/usr/bin/env bash
# Module boundaries: with render's include path, a file that includes render's allowed
# headers compiles and one that includes an lsystem/ header does not.
set -u
build="$1"
if ! out=$(cmake --build "$build" --target boundary_render_allowed 2>&1); then
  echo "FAIL: the allowed-includes control does not compile:"; echo "$out"; exit 1
fi
if out=$(cmake --build "$build" --target boundary_render_forbidden 2>&1); then
  echo "FAIL: render/ compiled a file that includes lsystem/skeleton.h"; exit 1
fi
# GCC and clang (the sanitizer build) word the missing header differently.
if ! grep -qE "lsystem/skeleton.h: No such file or directory|'lsystem/skeleton.h' file not found" <<<"$out"; then
  echo "FAIL: the forbidden include failed for another reason:"; echo "$out"; exit 1
fi
echo "module boundaries hold: render/ cannot include lsystem/"
