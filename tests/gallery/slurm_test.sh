#!/usr/bin/env bash
# The gallery on a real scheduler (ctest `gallery_slurm`, labelled heavy): a one-node Slurm
# cluster (munged, slurmctld, slurmd on localhost, as plain processes: no systemd) started
# in a temporary folder, then docs/GALLERY.md's recipe run on it:
#   1. the job script of docs/GALLERY.md "Slurm job array", submitted as an array of 3 tasks
#      (--array=1-5:2, so SLURM_ARRAY_TASK_MIN and _STEP matter) over 4 species, and the
#      merge as the dependent job of the same section; every task and the merge end with
#      exit code 0;
#   2. the merged gallery equals an unsharded gallery of the same species byte for byte
#      (images, thumbnails, pages; index.html and pages without their timing cells) and the
#      shards' manifests list the same items as the unsharded one (timings aside), each
#      manifest naming its own shard of 3;
#   3. resubmitting the array with `sbatch --wait` after one species' image was deleted
#      renders that species alone (the others are up to date) and restores the same bytes.
# slurm.conf is the block of docs/GALLERY.md "A one-node cluster", with this test's folder and
# two free ports. Everything is stopped and removed when the test ends, also on failure.
# slurm.conf's SlurmUser (and SlurmdUser) become the user running the test: root in CI, any
# other user as well (jobs then run as that user). Exits 77 (ctest: skipped, and says why)
# only where no cluster can be started: the Slurm or munge programs are missing
# (scripts/install-deps.sh installs them).
# Usage: tests/gallery/slurm_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
SPRIG=$(realpath "$1")
SRC=$(pwd)
source "$SRC/tests/gallery/lib.sh"
skip() { echo "SKIPPED: gallery_slurm: $* -- the gallery was NOT run on Slurm" >&2; exit 77; }

# The daemons live in /usr/sbin, which a user's PATH may lack.
PATH=$PATH:/usr/sbin:/sbin
for p in munged mungekey slurmctld slurmd sbatch scontrol sinfo squeue scancel srun python3; do
  command -v "$p" > /dev/null || skip "the program $p is missing (Debian: slurm-wlm, munge; scripts/install-deps.sh)"
done

# slurmd 22.05 starts only where the control groups are mounted (any booted system; not a
# bare chroot or a container without them).
grep -q ' /sys/fs/cgroup ' /proc/mounts || skip "no control groups mounted on /sys/fs/cgroup (slurmd needs them)"

# The cluster's folder: munged wants its socket's folder searchable by everyone and nothing
# in it writable by others.
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-slurm-test-XXXXXX")
chmod 711 "$WORK"
pids=()
stop_cluster() {
  set +e
  if [ -n "${SLURM_CONF:-}" ] && [ -f "$SLURM_CONF" ]; then
    scancel --quiet --full $(squeue -h -o %A 2>/dev/null) 2>/dev/null
  fi
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill "${pids[i]}" 2>/dev/null; done
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null
  done
  wait 2>/dev/null
  # A job step outliving its slurmd (slurmstepd or sprig, all named after this folder).
  leftover=$(pgrep -f "$WORK" || true)
  [ -n "$leftover" ] && kill -KILL $leftover 2>/dev/null
  rm -rf "$WORK"
}
trap stop_cluster EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
dump_logs() {
  for f in "$WORK"/*.log "$WORK"/log/*; do echo "== $f"; tail -n 30 "$f"; done >&2
}

# --- the species: the sharding test's three trees and a BlobTree, all tiny --------------
mkdir -p "$WORK/lib/species" "$WORK/lib/grammars" "$WORK/log" "$WORK/state" "$WORK/spool"
cp "$SRC"/tests/gallery/species/*.yaml "$WORK/lib/species/"
cp "$SRC"/grammars/abop_1_24a.lsys "$SRC"/grammars/shrub.lsys "$SRC"/grammars/growth_timed.lsys "$WORK/lib/grammars/"
cp "$SRC"/tests/gallery/blob_ball.yaml "$WORK/lib/species/"
# The job script calls build/sprig from the checkout: here the checkout is lib/.
ln -s "$(dirname "$SPRIG")" "$WORK/lib/build"
cd "$WORK/lib"

# The unsharded reference, rendered while the cluster starts.
"$SPRIG" --threads 1 gallery -o "$WORK/ref" --quality final 2> "$WORK/log/reference" &
ref_pid=$!

# --- the cluster ----------------------------------------------------------------------
mungekey --create --keyfile="$WORK/munge.key"
munged -F --key-file="$WORK/munge.key" --socket="$WORK/munge.socket" --pid-file="$WORK/munged.pid" \
  --seed-file="$WORK/munged.seed" --log-file="$WORK/munged.log" 2> "$WORK/log/munged" &
pids+=($!)
for _ in $(seq 100); do [ -S "$WORK/munge.socket" ] && break; sleep 0.1; done
[ -S "$WORK/munge.socket" ] || { dump_logs; fail "munged did not start"; }

# The daemons run as whoever runs the test (root in CI; another user runs jobs as itself).
user=$(id -un)
read -r ctld_port slurmd_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
awk '/^<!-- slurm.conf:/ {want = 1; next} want && /^```/ {if (inside) exit; inside = 1; next} inside' "$SRC/docs/GALLERY.md" |
  sed -e "s|FOLDER|$WORK|g" -e "s|^SlurmUser=.*|SlurmUser=$user\nSlurmdUser=$user|" -e "s|^SlurmctldPort=.*|SlurmctldPort=$ctld_port|" -e "s|^SlurmdPort=.*|SlurmdPort=$slurmd_port|" \
  > "$WORK/slurm.conf"
grep -q '^NodeName=' "$WORK/slurm.conf" && grep -q "^AuthInfo=socket=$WORK/munge.socket$" "$WORK/slurm.conf" ||
  fail "no slurm.conf block (with FOLDER/munge.socket) found in docs/GALLERY.md"
export SLURM_CONF=$WORK/slurm.conf
slurmctld -D > "$WORK/log/slurmctld" 2>&1 &
pids+=($!)
node=$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' "$SLURM_CONF")
slurmd -D -N "$node" > "$WORK/log/slurmd" 2>&1 &
pids+=($!)
state=
for _ in $(seq 300); do
  state=$(sinfo -h -N -o %t 2> /dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.1
done
[ "$state" = idle ] || { dump_logs; fail "the node is not idle 30 s after the daemons started (state: '$state')"; }
echo "gallery_slurm: cluster up at ${SECONDS} s"

# "TASK STATE EXIT" per task of job $1 ("-" for TASK outside an array), sorted. `scontrol`
# keeps a finished job for MinJobAge (300 s): no accounting daemon is needed.
job_table() {
  scontrol -o show job "$1" 2> /dev/null | while read -r line; do
    field() { grep -o " $1=[^ ]*" <<< " $line" | head -1 | cut -d= -f2; }
    task=$(field ArrayTaskId)
    echo "${task:--} $(field JobState) $(field ExitCode)"
  done | sort
}
# Waits up to $2 seconds for every task of job $1 to end, polling twice a second. (`sbatch
# --wait` looks 2, 10 and 42 s after submitting, measured with `--wrap 'sleep 11'`: on it
# the array and merge below took 14 to 43 s.)
wait_job() {
  local end=$((SECONDS + $2)) states
  while [ "$SECONDS" -lt "$end" ]; do
    states=$(job_table "$1" | cut -d' ' -f2 | sort -u)
    if [ -n "$states" ] && ! grep -qvE '^(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)$' <<< "$states"; then
      return 0
    fi
    sleep 0.5
  done
  return 1
}

# --- 1. docs/GALLERY.md's job script as an array of 3 tasks, then the dependent merge -----
awk '/^<!-- gallery.sbatch:/ {want = 1; next} want && /^```/ {if (inside) exit; inside = 1; next} inside' \
  "$SRC/docs/GALLERY.md" | sed "s|/shared/gallery|$WORK/out|g" > "$WORK/gallery.sbatch"
grep -q '^srun .*build/sprig .* gallery ' "$WORK/gallery.sbatch" || fail "no job script found in docs/GALLERY.md"
# The script's own directives ask for 16 tasks of 4 CPUs; options on the command line win.
# Two tasks run at a time (CPUs=2), each with one thread.
submit=(sbatch --array=1-5:2 --cpus-per-task=1 --time=00:05:00 --output="$WORK/log/task-%a")
jid=$("${submit[@]}" --parsable "$WORK/gallery.sbatch")
mjid=$(sbatch --parsable --dependency=afterany:"$jid" --output="$WORK/log/merge" --wrap "build/sprig gallery --merge $WORK/out")
wait_job "$mjid" 240 || { dump_logs; fail "the merge job has not ended after 240 s: $(job_table "$mjid")"; }
[ "$(job_table "$mjid")" = "- COMPLETED 0:0" ] || { dump_logs; fail "the merge job: $(job_table "$mjid")"; }
# Every task of the array ended before the merge, each with exit code 0.
tasks=$(job_table "$jid")
[ "$tasks" = "$(printf '1 COMPLETED 0:0\n3 COMPLETED 0:0\n5 COMPLETED 0:0')" ] || { dump_logs; fail "array tasks: $tasks"; }
echo "gallery_slurm: array and merge done at ${SECONDS} s"
wait "$ref_pid" || { cat "$WORK/log/reference"; fail "the unsharded gallery failed"; }

# --- 2. the merged gallery equals the unsharded one ------------------------------------
[ -f "$WORK/out/index.html" ] || fail "the merge wrote no index.html"
for i in 0 1 2; do
  m="$WORK/out/manifests/shard-$i-of-3.json"
  [ -f "$m" ] || { ls "$WORK/out/manifests"; fail "no manifest of shard $i of 3"; }
  grep -q "\"shard\": $i, \"shards\": 3, \"quality\": \"final\"" "$m" || fail "$m names another shard"
done
[ "$(ls "$WORK/out/manifests")" = "$(printf 'shard-0-of-3.json\nshard-1-of-3.json\nshard-2-of-3.json')" ] ||
  fail "other manifests than the three shards': $(ls "$WORK/out/manifests")"
same_gallery "$WORK/ref" "$WORK/out"
same_manifest_items "$WORK/ref" "$WORK/out"
[ "$(grep -c '^ *{"source": ' "$WORK"/out/manifests/*.json | cut -d: -f2 | sort | tr '\n' ' ')" = "1 1 2 " ] ||
  fail "4 species over 3 shards should give 2, 1 and 1 items"

# --- 3. a resubmitted array renders only what is missing ------------------------------
rm "$WORK/out/shrub.png"
timeout 240 "${submit[@]}" --wait "$WORK/gallery.sbatch" > /dev/null || { dump_logs; fail "the resubmitted array failed"; }
rendered=$(cat "$WORK"/log/task-* | grep -o 'shard [0-9]/3: [0-9]* rendered, [0-9]* up to date' | sort)
[ "$rendered" = "$(printf 'shard 0/3: 0 rendered, 2 up to date\nshard 1/3: 0 rendered, 1 up to date\nshard 2/3: 1 rendered, 0 up to date')" ] ||
  { dump_logs; fail "the resubmitted array should render shrub alone: $rendered"; }
cmp -s "$WORK/ref/shrub.png" "$WORK/out/shrub.png" || fail "shrub.png differs after the resubmission"
echo "gallery_slurm: resubmitted array done at ${SECONDS} s"

echo "gallery_slurm: all checks passed (3 array tasks on a one-node Slurm $(sinfo -V | cut -d' ' -f2) cluster, merged gallery = unsharded gallery)"
