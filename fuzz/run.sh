#!/usr/bin/env bash
# Runs every fuzz target of fuzz/ for SECONDS each (make fuzz FUZZ_SECONDS=N):
#   fuzz/run.sh BUILD_DIR SECONDS [TARGET...]
# Corpora live in BUILD_DIR/fuzz-corpus/<target>/, seeded on first use from the shipped
# grammars/, species/, base meshes and textures; the inputs in fuzz/regressions/<target>/
# are read too. Any crash, leak, timeout or out-of-memory input libFuzzer finds is copied
# into fuzz/regressions/<target>/ (which ctest replays, fuzz_regressions_<target>) and the
# script fails. One summary line per target: executions, exec/s, coverage (cov, ft), corpus.
# FUZZ_JOBS (default: the number of cores) targets run at once.
# Run from the repository root.
set -u
BUILD=${1:?usage: fuzz/run.sh BUILD_DIR SECONDS [TARGET...]}
SECS=${2:?usage: fuzz/run.sh BUILD_DIR SECONDS [TARGET...]}
shift 2
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(grammar view background function enviro expression derive species_tree species_shell species_blob species_organism species_solid polymesh image volume)
ROOT=$(pwd)
# The sanitizer settings of the Makefile, also when this script is run by hand.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$ROOT/fuzz/lsan.supp:print_suppressions=0}
status=0

# seed TARGET FOLDER: the first corpus of a target from the repository's own files.
seed() {
  local t=$1 dir=$2 f i=0
  case $t in
    grammar | derive)
      cp grammars/*.lsys "$dir"/
      for f in tests/assets/cpfg/*/*.l; do cp "$f" "$dir/$(basename "$(dirname "$f")").l"; done ;;
    view)
      for f in tests/assets/cpfg/*/*.v; do cp "$f" "$dir/$(basename "$(dirname "$f")").v"; done ;;
    background)
      cp tests/assets/cpfg/background/background.dat "$dir"/
      for f in tests/bad_inputs/inputs/cpfg/background_*/scene.dat; do cp "$f" "$dir/$(basename "$(dirname "$f")").dat"; done ;;
    function)
      # The first byte picks the reader (fuzz/function.cpp): 0 function, 1 curve, 2 contour,
      # 3 surface, 4 materials file.
      for f in tests/assets/cpfg/*/*.func; do { printf '\x00'; cat "$f"; } >"$dir/$(basename "$f")"; done
      for f in tests/assets/cpfg/curve/*.con; do { printf '\x01'; cat "$f"; } >"$dir/curve-$(basename "$f")"; done
      for f in tests/assets/cpfg/contour/*.con; do { printf '\x02'; cat "$f"; } >"$dir/$(basename "$f")"; done
      for f in tests/assets/cpfg/*/*.s grammars/vlab/*/*.s; do { printf '\x03'; cat "$f"; } >"$dir/$(basename "$(dirname "$f")")-$(basename "$f")"; done
      # Two patches that name each other as neighbours (the connection check).
      patch() { printf '%s\nTOP COLOR: 1 DIFFUSE: 0.5 BOTTOM COLOR: 2 DIFFUSE: 0.5\nAL: ~ A: ~ AR: ~\nL: %s R: %s\nBL: ~ B: ~ BR: ~\n' "$1" "$2" "$3"
               for r in 0 1 2 3; do printf '%s 0 %s  %s 1 %s  %s 2 %s  %s 3 %s\n' $4 $r $4 $r $4 $r $4 $r; done; }
      { printf '\x03-1 1 0 3 0 3\nCONTACT POINT X: 0 Y: 0 Z: 0\nEND POINT X: 0 Y: 3 Z: 0\nHEADING X: 0 Y: 1 Z: 0\nUP X: 0 Y: 0 Z: 1\nSIZE: 3\n'
        patch left '~' right 0; patch right left '~' 1; } >"$dir/two_patches.s"
      # 4: materials files (binary records of 15 bytes): the test objects', one record, and
      # the same index twice with a transparency.
      for f in tests/assets/cpfg/*/*.mat; do { printf '\x04'; cat "$f"; } >"$dir/$(basename "$(dirname "$f")")-$(basename "$f")"; done
      printf '\x04\x07\x00\x10\x20\x30\x40\x50\x60\x00\x00\x00\xff\xff\xff\x20' >"$dir/one_material.mat"
      printf '\x04\x01\x80\x00\x00\x00\xff\x00\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x00\x00\xff\x00\x00\x00\x00\x00\x00\x00\x00' >"$dir/twice.mat" ;;
    enviro)
      # The first byte picks the reader (fuzz/enviro.cpp): even, the environment file;
      # odd, a program's answer lines.
      for f in tests/assets/cpfg/enviro/*/*.e tests/bad_inputs/inputs/cpfg/enviro/*.e; do
        { printf '\x00'; cat "$f"; } >"$dir/$(basename "$(dirname "$f")")-$(basename "$f")"
      done
      printf '\x0112 E(0.5)\n0 E\n30 E(,1.5,)\n7 E(1e3, -2)\n' >"$dir/answers"
      printf '\x01 ;:4 E()\n5 xE(1,,)\n' >"$dir/answers_blank" ;;
    expression)
      for e in 't' 'x*0.9' 'sin(t)*x' 'max(0, 1 - t^2)' 'sqrt(x) + pow(t, 2) / 3' 'atan2(x, t) > 45 && t < 1' \
               'floor(x) == ceil(x) || !t' '-(-(-x))' 'min(t, max(x, 1e-3))' 'exp(log(t + 1))'; do
        printf '%s' "$e" >"$dir/e$((i++))"
      done ;;
    species_*)
      local kind=${t#species_}
      for f in species/*.yaml tests/gallery/species/*.yaml; do
        [ -f "$f" ] || continue
        grep -qx "kind: $kind" "$f" || continue
        grep -vx "kind: $kind" "$f" >"$dir/$(basename "$f")"
      done
      # Species with the files they name carried in the input (fuzz/species.cpp, `#%file`):
      # base meshes of an organism, an extrude_2d mask of a solid (healthy ones; the
      # degenerate and extreme ones are in fuzz/regressions/<target>/, read as corpus too).
      local tet='v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n'
      local quad='v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n'
      local mask='P3\n3 3\n255\n255 255 255 0 0 0 255 255 255\n0 0 0 0 0 0 0 0 0\n255 255 255 0 0 0 255 255 255\n'
      case $kind in
        organism)
          printf "organism:\n  levels: 2\n  base: {mesh: {file: base.obj}}\n  detail:\n    - rock: {amplitude: 0.1, frequency: 2}\n#%%file base.obj\n$tet" >"$dir/file_tet.yaml"
          printf "organism:\n  levels: 3\n  base: {mesh: {file: base.obj, center: true, size: 2}}\n#%%file base.obj\n$quad" >"$dir/file_quad.yaml" ;;
        solid)
          printf "solid:\n  volume:\n    distance_field: {extrude_2d: {file: mask.ppm, size: [2, 2], height: [0, 1]}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n#%%file mask.ppm\n$mask" >"$dir/file_extrude.yaml"
          printf "solid:\n  volume:\n    distance_field: {surface_mesh: {file: base.obj}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n#%%file base.obj\n$tet" >"$dir/file_mesh.yaml" ;;
      esac ;;
    polymesh)
      for f in species/meshes/*.off tests/bad_inputs/inputs/*.obj; do
        [ -f "$f" ] && [ "$(stat -c %s "$f")" -le 65536 ] || continue
        case $f in *.obj) p='\x00' ;; *.ply) p='\x01' ;; *) p='\x02' ;; esac
        { printf "$p"; cat "$f"; } >"$dir/$(basename "$f")"
      done
      printf '\x01ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$dir/tri.ply"
      printf '\x00v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n' >"$dir/tet.obj" ;;
    image)
      for f in textures/maps/*.png; do
        [ "$(stat -c %s "$f")" -le 65536 ] || continue
        { printf '\x00'; cat "$f"; } >"$dir/$(basename "$f")"
      done
      printf '\x05P3\n2 2\n255\n255 0 0 0 255 0 0 0 255 255 255 255\n' >"$dir/tiny.ppm" ;;
    volume)
      # A 4^3 float volume with one dense voxel, and an 8-bit big-endian one; header padded to 256.
      inr() { local h="#INRIMAGE-4#{"$'\n'"$1"; while [ $(( (${#h} + 4) % 256 )) -ne 0 ]; do h+=$'\n'; done; printf '%s##}\n' "$h"; }
      { inr $'XDIM=4\nYDIM=4\nZDIM=4\nTYPE=float\nPIXSIZE=32 bits\nCPU=decm\n'; head -c 84 /dev/zero; printf '\x00\x00\x80\x3f'; head -c 168 /dev/zero; } >"$dir/one.inr"
      { inr $'XDIM=3\nYDIM=3\nZDIM=3\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nCPU=sun\nVX=0.5\n'; printf '\x00%.0s' $(seq 13); printf '\xff'; printf '\x00%.0s' $(seq 13); } >"$dir/byte.inr"
      cp tests/bad_inputs/inputs/damaged.inr "$dir/" ;;
  esac
}

dict_of() {
  case $1 in
    grammar | derive) echo fuzz/dict/grammar.dict ;;
    view) echo fuzz/dict/view.dict ;;
    background) echo fuzz/dict/background.dict ;;
    function) echo fuzz/dict/cpfg_files.dict ;;
    enviro) echo fuzz/dict/enviro.dict ;;
    expression) echo fuzz/dict/expression.dict ;;
    species_*) echo fuzz/dict/yaml.dict ;;
    polymesh) echo fuzz/dict/mesh.dict ;;
    *) echo "" ;;
  esac
}

# run_one TARGET: one libFuzzer run; its summary line (and, on failure, the report) goes to
# BUILD/fuzz-TARGET.summary, and the file BUILD/fuzz-TARGET.failed marks a failure.
run_one() {
  local t=$1 exe="$BUILD/fuzz/fuzz_$1" corpus="$BUILD/fuzz-corpus/$1" art="$BUILD/fuzz-artifacts/$1"
  local sum="$BUILD/fuzz-$1.summary" log="$BUILD/fuzz-$1.log" dict rc last execs rate cov ft found
  rm -f "$BUILD/fuzz-$t.failed"
  [ -x "$exe" ] || { echo "fuzz: $exe is not built" >"$sum"; touch "$BUILD/fuzz-$t.failed"; return; }
  mkdir -p "$corpus" "$art" "fuzz/regressions/$t"
  [ -n "$(ls -A "$corpus")" ] || seed "$t" "$corpus"
  dict=$(dict_of "$t")
  # One process, SECS of wall time; memory capped so an input that allocates without bound
  # is reported as oom-* rather than taking the machine.
  # The run's CPU seconds (user + system) are reported too: on a busy machine they are less
  # than its wall time.
  local TIMEFORMAT='%U %S' cpu
  { time "$exe" -max_total_time="$SECS" -rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$art/" ${dict:+-dict=$dict} "$corpus" "fuzz/regressions/$t" >"$log" 2>&1; } 2>"$BUILD/fuzz-$t.cpu"
  rc=$?
  cpu=$(awk '{printf "%.0f", $1 + $2}' "$BUILD/fuzz-$t.cpu")
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  execs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$')
  rate=$(grep -oE 'stat::average_exec_per_sec: *[0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$')
  cov=$(echo "$last" | grep -oE 'cov: [0-9]+' | grep -oE '[0-9]+')
  ft=$(echo "$last" | grep -oE 'ft: [0-9]+' | grep -oE '[0-9]+')
  found=$(find "$art" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
  printf 'fuzz %-17s %4ss (cpu %4ss)  execs %-9s exec/s %-6s cov %-6s ft %-6s corpus %-5s found %s\n' \
    "$t" "$SECS" "${cpu:-?}" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$(ls "$corpus" | wc -l)" "$found" >"$sum"
  if [ "$found" -gt 0 ] || [ $rc -ne 0 ]; then
    touch "$BUILD/fuzz-$t.failed"
    cp "$art"/crash-* "$art"/leak-* "$art"/timeout-* "$art"/oom-* "fuzz/regressions/$t/" 2>/dev/null
    { echo "  fuzz_$t failed (exit $rc): inputs copied to fuzz/regressions/$t/; log $log"
      grep -m3 -E 'ERROR|SUMMARY|runtime error' "$log" | sed 's/^/  /'; } >>"$sum"
  fi
}

# FUZZ_JOBS targets at a time (default: one per core), each a single-core libFuzzer process
# for SECS of wall time; summaries are printed in the targets' order.
JOBS=${FUZZ_JOBS:-$(nproc)}
running=0
for t in "${TARGETS[@]}"; do
  if [ "$running" -ge "$JOBS" ]; then wait -n; running=$((running - 1)); fi
  run_one "$t" &
  running=$((running + 1))
done
wait
for t in "${TARGETS[@]}"; do
  cat "$BUILD/fuzz-$t.summary"
  [ -e "$BUILD/fuzz-$t.failed" ] && status=1
done
cd "$ROOT"
exit $status
