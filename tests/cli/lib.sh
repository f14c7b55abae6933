# Sourced by the CLI tests after `set -euo pipefail`, with the test's arguments:
#   SPRIG   the sprig binary given as $1, made absolute
#   WORK    a fresh folder, removed when the test exits
#   fail    prints "FAIL: message" to stderr and exits 1
#   sprig   runs the binary with --quiet
SPRIG=$(realpath "${1:?usage: $0 path/to/sprig}")
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-cli-test-XXXXXX")
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
sprig() { "$SPRIG" --quiet "$@"; }
