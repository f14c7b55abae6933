#!/usr/bin/env bash
# Installs the Debian 12 packages Sprig needs, only those missing.
# Checked with dpkg -s; installed with apt-get (after apt-get update) only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libembree-dev libtbb-dev libopenimageio-dev openimageio-tools libpng-dev
  libosd-dev libyaml-cpp-dev catch2 libcli11-dev libtinygltf-dev libopenvdb-dev libboost-iostreams-dev zlib1g-dev
  libbenchmark-dev parallel
  libmeshoptimizer-dev libcgal-demo
  libeigen3-dev
  fonts-dejavu-core fonts-dejavu-extra  # the fonts of cpfg's @L labels (docs/GRAMMAR.md, "Labels")
  nodejs curl ca-certificates
  python3-yaml  # tests: scripts/gltf-parts.py reads species files on its own
  gmsh
  clang-14 libclang-rt-14-dev ccache
  chromium  # tests: headless Chromium loads the gallery (tests/gallery/browser_test.sh)
  slurm-wlm munge  # tests: a one-node Slurm cluster runs the gallery as a job array (tests/gallery/slurm_test.sh)
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module (python/, docs/PYTHON.md) and its tests
  blender  # tests: the Blender add-on (blender/, docs/BLENDER.md), ctest blender_addon
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg -s "$p" >/dev/null 2>&1 || ! dpkg -s "$p" 2>/dev/null | grep -q '^Status: install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
echo "sprig: installing missing packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator (npm package gltf-validator, Apache-2.0), for the tests that
# read Sprig's .glb files back: one pinned tarball, checked by its SHA-256, unpacked under
# tools/ (not committed). Node.js runs it (scripts/gltf-validate.js).
validator_version=2.0.0-dev.3.10
validator_sha256=4e03dbdc3bc0d1342afd5d2d7ae341a7e3474502ccb872b02dbbaddaee0fdec6
validator_dir="$(dirname "$0")/../tools/node_modules/gltf-validator"
if [ ! -f "$validator_dir/package.json" ] || ! grep -q "\"version\": \"$validator_version\"" "$validator_dir/package.json"; then
  echo "sprig: fetching the glTF validator $validator_version"
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
  url="https://registry.npmjs.org/gltf-validator/-/gltf-validator-$validator_version.tgz"
  # The SHA-256 below, not TLS, vouches for the file: where a proxy re-signs HTTPS with a
  # certificate this system does not know, the download goes on without verifying it.
  if ! curl -sSfL --retry 3 -o "$tmp/v.tgz" "$url" 2>"$tmp/err"; then
    if grep -q "certificate" "$tmp/err"; then
      echo "sprig: the registry's TLS certificate is not trusted here; relying on the SHA-256 check"
      curl -sSfL --retry 3 --insecure -o "$tmp/v.tgz" "$url"
    else
      cat "$tmp/err" >&2
      exit 1
    fi
  fi
  echo "$validator_sha256  $tmp/v.tgz" | sha256sum -c --quiet -
  tar xzf "$tmp/v.tgz" -C "$tmp"
  rm -rf "$validator_dir"
  mkdir -p "$(dirname "$validator_dir")"
  mv "$tmp/package" "$validator_dir"
fi

# npm packages the tests run, each installed from its lock file under tools/NAME (not
# committed): npm ci installs exactly the versions of scripts/NAME/package-lock.json, each
# checked by its integrity hash. Usage: npm_locked NAME BIN (BIN: the installed program
# whose presence means "installed").
npm_locked() {
  local name=$1 bin=$2 dir
  dir="$(dirname "$0")/../tools/$name"
  if [ -x "$dir/node_modules/.bin/$bin" ] && cmp -s "$(dirname "$0")/$name/package-lock.json" "$dir/package-lock.json"; then
    return 0
  fi
  echo "sprig: installing $name (scripts/$name/package-lock.json)"
  if ! command -v npm >/dev/null; then  # Debian's nodejs comes without npm; NodeSource's has it
    $([ "$(id -u)" -ne 0 ] && echo sudo) apt-get install -y -q --no-install-recommends npm
  fi
  mkdir -p "$dir"
  cp "$(dirname "$0")/$name/package.json" "$(dirname "$0")/$name/package-lock.json" "$dir/"
  # As for the validator above, the lock file's integrity hashes (SHA-512 of every
  # tarball), not TLS, vouch for the packages: where a proxy re-signs HTTPS with a
  # certificate this system does not know, npm retries without verifying it.
  if ! (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error) 2>"$dir/npm-err.txt"; then
    if grep -q "CERT\|certificate" "$dir/npm-err.txt"; then
      echo "sprig: the npm registry's TLS certificate is not trusted here; relying on the lock file's integrity hashes"
      (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error --strict-ssl=false)
    else
      cat "$dir/npm-err.txt" >&2
      exit 1
    fi
  fi
  rm -f "$dir/npm-err.txt"
}

# ajv-cli 5.0.0 (MIT), the independent JSON Schema validator that checks `sprig schema`
# against every shipped species (tests/cli/schema_test.sh), into tools/ajv.
npm_locked ajv ajv
# yaml-language-server 1.25.0 (MIT), the YAML language server of VS Code's YAML extension,
# Neovim's yamlls and most other editors: tests/editor/run.sh checks that it reports what
# `sprig check` reports, through `sprig schema`; into tools/yaml-language-server. (2.x
# needs Node.js 22 or newer; the project's machines have 20.)
npm_locked yaml-language-server yaml-language-server
