#!/usr/bin/env bash
# Proves the README's promise on a bare Debian 12 system.
#
# Builds a minimal bookworm root file system with `debootstrap --variant=minbase`, adds only
# `make` and `git`, clones this repository at HEAD into it, and runs `make test` there as root
# (and `make gallery` with --gallery). Every step prints its time. Mounts and the folder are
# removed on exit, also when interrupted.
#
#   scripts/fresh-machine-test.sh [--gallery] [--keep] [--cache DIR] [--mirror URL] [--no-ccache]
#
#   --gallery     also run `make gallery` after `make test`
#   --keep        leave the root file system in place (its path is printed)
#   --no-ccache   compile everything anew; by default the host's compiler cache (ccache's
#                 cache_dir, when ccache is installed) is mounted into the new system, so
#                 objects the host already compiled from the same sources with the same
#                 Debian compiler are reused. Every package is still installed from scratch
#                 and every header is still read from the new system, so a missing package
#                 still fails the build.
#   --cache DIR   where downloaded .deb files are kept between runs on this machine
#                 (default /var/cache/sprig-fresh-machine). Only downloads are cached,
#                 never an installed system: every run installs everything from scratch.
#   --mirror URL  Debian archive (default http://deb.debian.org/debian)
#
# Needs root, network access to Debian's archive and about 4 GB of disk.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
gallery=0
keep=0
cache=/var/cache/sprig-fresh-machine
mirror=http://deb.debian.org/debian
use_ccache=1
while [ $# -gt 0 ]; do
  case "$1" in
    --gallery) gallery=1 ;;
    --keep) keep=1 ;;
    --cache) cache="$2"; shift ;;
    --mirror) mirror="$2"; shift ;;
    --no-ccache) use_ccache=0 ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) echo "fresh-machine-test: error: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

if [ "$(id -u)" -ne 0 ]; then
  echo "fresh-machine-test: error: must run as root (debootstrap and chroot)" >&2
  exit 2
fi

step_start=0
step() { step_start=$(date +%s); echo "== fresh-machine: $*"; }
done_step() { echo "== fresh-machine: $1 took $(( $(date +%s) - step_start )) s"; }

# The host tools this script itself uses.
if ! command -v debootstrap >/dev/null 2>&1; then
  step "installing debootstrap on the host"
  DEBIAN_FRONTEND=noninteractive apt-get update -q
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends debootstrap
  done_step "installing debootstrap"
fi

root="$(mktemp -d /var/tmp/sprig-fresh.XXXXXX)"
# mktemp makes the folder 0700; as the new system's / it must let its system users (munge's
# post-installation script runs /bin/sh as `munge`) reach their programs.
chmod 0755 "$root"
mkdir -p "$cache/debootstrap" "$cache/apt"

# Mount points under $root, innermost last; unmounted in reverse order.
mounts=()
mount_into() {  # mount_into TARGET MOUNT-ARGS...
  local target="$root/$1"; shift
  mkdir -p "$target"
  mount "$@" "$target"
  mounts+=("$target")
}

cleanup() {
  local rc=$?
  trap - EXIT INT TERM
  # Stop anything still running inside the root (an interrupted build).
  for p in /proc/[0-9]*; do
    if [ "$(readlink "$p/root" 2>/dev/null)" = "$root" ]; then
      kill -9 "${p#/proc/}" 2>/dev/null || true
    fi
  done
  local i
  for (( i=${#mounts[@]}-1; i>=0; i-- )); do
    umount -R "${mounts[$i]}" 2>/dev/null || umount -l "${mounts[$i]}" 2>/dev/null || true
  done
  if grep -q " $root/" /proc/mounts; then
    echo "fresh-machine-test: error: mounts remain under $root; not deleting it" >&2
    rc=1
  elif [ "$keep" -eq 1 ]; then
    echo "== fresh-machine: root file system kept at $root"
  else
    rm -rf --one-file-system "$root"
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

total_start=$(date +%s)

step "debootstrap --variant=minbase bookworm ($root)"
debootstrap --variant=minbase --cache-dir="$cache/debootstrap" bookworm "$root" "$mirror" \
  > "$cache/debootstrap.log" 2>&1 || { tail -20 "$cache/debootstrap.log" >&2; exit 1; }
done_step "debootstrap"

# A fresh Debian 12 machine: the release, its updates and its security archive.
cat > "$root/etc/apt/sources.list" <<EOF
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount_into proc -t proc proc
mount_into sys -t sysfs sysfs
# A booted Debian system has its control groups mounted; slurmd (the gallery_slurm test's
# one-node cluster) refuses to start without them.
# --rbind takes the hierarchies mounted under it; --make-rslave keeps the unmounting at the
# end from reaching the host's own.
if grep -q ' /sys/fs/cgroup ' /proc/mounts; then mount_into sys/fs/cgroup --rbind --make-rslave /sys/fs/cgroup; fi
mount_into dev --bind /dev
mount_into dev/pts --bind /dev/pts
mount_into var/cache/apt/archives --bind "$cache/apt"
if [ "$use_ccache" -eq 1 ] && command -v ccache >/dev/null 2>&1; then
  ccache_dir="$(ccache --get-config cache_dir 2>/dev/null || true)"
  if [ -n "$ccache_dir" ]; then
    mkdir -p "$ccache_dir"
    mount_into root/.cache/ccache --bind "$ccache_dir"
    echo "== fresh-machine: sharing the host's compiler cache $ccache_dir (--no-ccache to compile anew)"
  fi
fi
# apt downloads as its own user: give it the cache (the uid the new system assigned).
chown -R "$(awk -F: '$1 == "_apt" {print $3}' "$root/etc/passwd")" "$cache/apt"

in_root() {
  chroot "$root" /usr/bin/env -i HOME=/root TERM=dumb LANG=C.UTF-8 CCACHE_MAXSIZE=20G \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
    /bin/bash -c "$1"
}

step "adding make and git"
in_root "apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends make git >/dev/null"
done_step "adding make and git"

step "cloning $(git -C "$repo" rev-parse --short HEAD)"
git clone -q --no-hardlinks "$repo" "$root/root/sprig"
git -C "$root/root/sprig" checkout -q --detach "$(git -C "$repo" rev-parse HEAD)"
done_step "cloning"

# `make test` in two timed parts: `make deps` (the set-up's package installation) is what
# `make test` runs first; running it alone first only splits the time, it changes nothing.
step "make deps (package installation)"
in_root "cd /root/sprig && make deps" > "$cache/make-deps.log" 2>&1 || { tail -40 "$cache/make-deps.log" >&2; exit 1; }
grep -m1 '^sprig: installing' "$cache/make-deps.log" || true
grep -m1 -E '^[0-9]+ upgraded, [0-9]+ newly installed' "$cache/make-deps.log" || true
done_step "make deps"

step "make test"
in_root "cd /root/sprig && make test"
done_step "make test"

if [ "$gallery" -eq 1 ]; then
  step "make gallery"
  in_root "cd /root/sprig && make gallery"
  count=$(find "$root/root/sprig/gallery/out" -name '*.png' | wc -l)
  echo "== fresh-machine: gallery has $count PNG files"
  done_step "make gallery"
fi

echo "== fresh-machine: all steps passed in $(( $(date +%s) - total_start )) s"
