#!/usr/bin/env bash
# Whole-process times of `sprig` commands that write no image (issue 19), and in the same
# run the baseline: the `lindenmayer` npm package deriving the same grammar in node.
#
#   bash bench/startup.sh [SPRIG] [STEPS]      (make bench runs it too)
#
# Times `sprig --version`, `sprig check grammars/abop_2_6.lsys`, `sprig derive
# grammars/abop_2_6.lsys --steps STEPS` (default 18) and `node
# bench/lindenmayer_abop_2_6.js STEPS` with hyperfine (installed with apt-get when missing
# and run as root), checks that both derivations wrote the same number of modules, and
# prints the ratio of the whole-process means. The npm package is installed into
# tools/bench-node/ (ignored by git; SPRIG_BENCH_NODE_DIR overrides), never by `make test`.
# RUNS (default 20) sets the runs of each sprig command; node gets 5.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
sprig=$(realpath "${1:-$repo/build/sprig}")
steps=${2:-18}
runs=${RUNS:-20}
grammar=$repo/grammars/abop_2_6.lsys
nodedir=${SPRIG_BENCH_NODE_DIR:-$repo/tools/bench-node}
driver=$repo/bench/lindenmayer_abop_2_6.js
lindenmayer_version=1.5.4

[[ -x $sprig ]] || { echo "startup.sh: no sprig binary at $sprig (build first)" >&2; exit 1; }
if ! command -v hyperfine >/dev/null; then
  if [[ $(id -u) == 0 ]]; then
    apt-get install -y hyperfine >/dev/null || { apt-get update >/dev/null && apt-get install -y hyperfine >/dev/null; }
  else
    echo "startup.sh: hyperfine is missing (apt-get install hyperfine)" >&2; exit 1
  fi
fi
command -v node >/dev/null && command -v npm >/dev/null ||
  { echo "startup.sh: node and npm are needed for the baseline (apt-get install nodejs npm)" >&2; exit 1; }
if [[ ! -f $nodedir/node_modules/lindenmayer/package.json ]]; then
  mkdir -p "$nodedir"
  npm install --prefix "$nodedir" --no-audit --no-fund --silent "lindenmayer@$lindenmayer_version" >/dev/null
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$repo"

# Same derivation, same module count.
sprig_line=$("$sprig" derive "$grammar" --steps "$steps")
sprig_modules=$(sed -E 's/.* ([0-9]+) modules.*/\1/' <<<"$sprig_line")
node_line=$(node "$driver" "$steps" "$nodedir")
node_modules=$(sed -E 's/.* ([0-9]+) modules.*/\1/' <<<"$node_line")
echo "sprig derive:  $sprig_line"
echo "lindenmayer:   $node_line (lindenmayer $(node -p "require('$nodedir/node_modules/lindenmayer/package.json').version"), node $(node --version))"
if [[ $sprig_modules != "$node_modules" ]]; then
  echo "startup.sh: the derivations differ: sprig $sprig_modules modules, lindenmayer $node_modules" >&2; exit 1
fi

# Shared libraries each process maps (the dynamic loader's count of objects it initialized).
libs() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -c 'calling init:' || true; }
rss() { /usr/bin/time -f %M "$@" 2>&1 >/dev/null | tail -1; }

echo "machine: $(nproc) cores; load before:$(uptime | sed 's/.*load average://')"
hyperfine -N --style none --warmup 3 --runs "$runs" --export-json "$tmp/sprig.json" \
  -n "sprig --version" "$sprig --version" \
  -n "sprig check abop_2_6.lsys" "$sprig check $grammar" \
  -n "sprig derive abop_2_6.lsys --steps $steps" "$sprig derive $grammar --steps $steps" >/dev/null
hyperfine -N --style none --warmup 1 --runs 5 --export-json "$tmp/node.json" \
  -n "node lindenmayer abop 2.6 --steps $steps" "node $driver $steps $nodedir" >/dev/null
echo "load after:$(uptime | sed 's/.*load average://')"

declare -a nlibs mem
nlibs[0]=$(libs "$sprig" --version); mem[0]=$(rss "$sprig" --version)
nlibs[1]=$(libs "$sprig" check "$grammar"); mem[1]=$(rss "$sprig" check "$grammar")
nlibs[2]=$(libs "$sprig" derive "$grammar" --steps "$steps"); mem[2]=$(rss "$sprig" derive "$grammar" --steps "$steps")
nlibs[3]=$(libs node "$driver" "$steps" "$nodedir"); mem[3]=$(rss node "$driver" "$steps" "$nodedir")

python3 - "$tmp/sprig.json" "$tmp/node.json" "${nlibs[@]}" "${mem[@]}" <<'PY'
import json, sys
results = json.load(open(sys.argv[1]))["results"] + json.load(open(sys.argv[2]))["results"]
libs, mem = sys.argv[3:7], sys.argv[7:11]
ms = lambda s: f"{s * 1000:9.1f}"
print(f"{'command':42} {'mean ms':>9} {'sd':>7} {'min':>9} {'user':>9} {'sys':>7} {'libs':>5} {'max RSS MB':>10}")
for r, n, m in zip(results, libs, mem):
    print(f"{r['command']:42} {ms(r['mean'])} {r['stddev'] * 1000:7.1f} {ms(r['min'])} {ms(r['user'])} {r['system'] * 1000:7.1f} "
          f"{n:>5} {int(m) / 1024:10.1f}")
check, derive, node = results[1], results[2], results[3]
print(f"sprig check, whole process: {check['mean'] * 1000:.1f} ms mean (target <= 30 ms)")
print(f"sprig derive vs lindenmayer, whole process: {node['mean'] / derive['mean']:.1f}x faster by means, "
      f"{node['min'] / derive['min']:.1f}x by minima (target >= 10x)")
PY
