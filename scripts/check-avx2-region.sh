#!/bin/bash
# Checks that the AVX2 copy of the batch walk stays in its region (blobtree/detail/batch_eval.cpp):
# in the object file, no function outside the namespace avx2:: holds an AVX (VEX-encoded)
# instruction, so no COMDAT copy of a header function (glm, the standard library,
# traverse.h) was compiled for AVX2 where the linker could pick it for the baseline path;
# and the AVX2 walk itself uses ymm registers. Usage: scripts/check-avx2-region.sh [build dir]
set -euo pipefail
obj=$(find "${1:-build}" -path '*sprig_blobtree.dir/*batch_eval.cpp.o' | head -1)
[ -n "$obj" ] || { echo "sprig: error: no batch_eval.cpp.o under ${1:-build}" >&2; exit 1; }
objdump -d --no-show-raw-insn -C "$obj" | awk -v obj="$obj" '
  /^[0-9a-f]+ <.*>:$/ { name = $0; avx2 = index(name, "::avx2::") > 0; next }
  /\tv[a-z0-9]+ / {
    if (!avx2) { bad[name]++ }
    else if (/%ymm/) { ymm++ }
  }
  END {
    for (n in bad) { printf "sprig: error: %s: AVX instructions outside the AVX2 region: %s\n", obj, n; failed = 1 }
    if (ymm == 0) { printf "sprig: error: %s: the AVX2 walk uses no ymm register\n", obj; failed = 1 }
    if (!failed) printf "%s: %d ymm instructions, all in avx2::\n", obj, ymm
    exit failed
  }'
