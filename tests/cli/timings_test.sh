#!/usr/bin/env bash
# `--timings json` (registered with ctest as `cli_timings`): an exact render of a small tree
# reports every phase of the command (start-up, read, derive, build, cells, scene, render,
# write, other), the phases add up to the reported total within 5 %, the named phases (all
# but "other") account for at least 90 % of it, and the total is the process's wall time
# (at most the wall time measured from outside, and at least 30 % of it). The same for a
# small layered solid, whose tetrahedra are built when the camera frames the model: that
# time is "build", not "other".
# Usage: tests/cli/timings_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"
cat >"$WORK/ball.yaml" <<'YAML'
kind: solid
solid:
  grid: {cell: 0.03}
  volume:
    distance_field: {sphere: {radius: 0.5}}
    layers:
      - interior_layer: {material: fired_clay, thickness: 0.12}
      - interior_layer: {material: bronze, thickness: fill}
render: {width: 48, height: 40, samples: 1}
YAML
python3 - "$SPRIG" "$WORK" <<'PY'
import json, subprocess, sys, time
sprig, work = sys.argv[1:]

def check(species, timed):
  args = [sprig, "--timings", "json", "render", species, "-o", work + "/t.png",
          "--width", "64", "--height", "64", "--spp", "1"]
  t0 = time.monotonic()
  p = subprocess.run(args, capture_output=True, text=True)
  wall = time.monotonic() - t0
  if p.returncode != 0:
      sys.exit("FAIL: sprig exited %d: %s" % (p.returncode, p.stderr))
  lines = [l for l in p.stderr.splitlines() if l.startswith("{")]
  if len(lines) != 1:
      sys.exit("FAIL: expected one JSON line on stderr, got: %r" % p.stderr)
  t = json.loads(lines[0])
  if t["command"] != "render":
      sys.exit("FAIL: command %r" % t["command"])
  phases = t["phases"]
  want = ["start-up", "read", "derive", "build", "cells", "scene", "render", "write", "other"]
  missing = [w for w in want if w not in phases]
  if missing:
      sys.exit("FAIL: phases missing: %s (got %s)" % (missing, list(phases)))
  for w in timed:
      if not phases[w] > 0:
          sys.exit("FAIL: phase %s took no time: %s" % (w, phases))
  total, summed = t["total"], sum(phases.values())
  if abs(summed - total) > 0.05 * total:
      sys.exit("FAIL: phases sum to %.4f s, total %.4f s" % (summed, total))
  # Unnamed time is small on an idle machine (4 % here); a loaded or sanitized run stretches
  # whatever is unnamed too, so the bound leaves room (one sanitized run under load failed at 5 %).
  if phases["other"] > 0.10 * total:
      sys.exit("FAIL: %.4f s of %.4f s in no named phase" % (phases["other"], total))
  # The total runs from the process's start to the JSON line, so it is at most the wall time
  # measured outside, and not far below it (the exit after the line, unloading libraries, is
  # all it misses, and LeakSanitizer's exit check in a sanitized build; generous, as the
  # machine may be loaded).
  if not (total <= wall + 0.01 and total >= 0.3 * wall):
      sys.exit("FAIL: reported total %.4f s, measured wall %.4f s" % (total, wall))
  print("ok: %s: %.3f s reported, %.3f s measured; %s" % (species, total, wall, ", ".join("%s %.3f" % kv for kv in phases.items())))

check("species/fig_tree_11_branching.yaml", ["read", "derive", "build", "cells", "scene", "render", "write"])
check(work + "/ball.yaml", ["read", "build", "scene", "render", "write"])
PY
