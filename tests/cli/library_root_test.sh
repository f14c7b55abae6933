#!/usr/bin/env bash
# The default library root and the species build cache (registered with ctest as `cli_library_root`):
#   1. a shipped species checks from the checkout root, from its own folder and from an
#      unrelated folder (the default root is the checkout, which holds .sprig-root);
#   2. a user species outside the checkout may use the files beside it, but not one above
#      its folder: that is refused with a hint naming --root, and --root of the folder above
#      accepts it;
#   3. a solid whose `species:` field is repeated by four levels of ten YAML aliases (11,111
#      references of one file) builds that species once: `check` ends in seconds (each
#      build of it takes about as long as the whole run).
# Usage: tests/cli/library_root_test.sh path/to/sprig   (run from the repository root)
set -euo pipefail
. "$(dirname "$0")/lib.sh"
CHECKOUT=$(pwd)

# --- 1. a shipped species from three folders ---------------------------------------------
sprig check species/shrub.yaml >/dev/null || fail "check from the checkout root"
(cd species && sprig check shrub.yaml >/dev/null) || fail "check from the species folder"
(cd "$WORK" && sprig check "$CHECKOUT/species/shrub.yaml" >/dev/null) || fail "check from another folder"

# --- 2. a user species outside the checkout ----------------------------------------------
mkdir -p "$WORK/plants"
cp grammars/abop_1_24a.lsys "$WORK/plants/beside.lsys"
cp grammars/abop_1_24a.lsys "$WORK/above.lsys"
printf 'kind: tree\ngrammar: beside.lsys\n' >"$WORK/plants/beside.yaml"
printf 'kind: tree\ngrammar: ../above.lsys\n' >"$WORK/plants/above.yaml"
(cd "$WORK" && sprig check plants/beside.yaml >/dev/null) || fail "a file beside a user species"
set +e
err=$(cd "$WORK" && sprig check plants/above.yaml 2>&1 >/dev/null)
rc=$?
set -e
[ $rc = 1 ] || fail "an escape above a user species: exit $rc"
[ "$err" = "plants/above.yaml:2:10: error: refusing path '../above.lsys': it leaves the library root 'plants' (pass --root FOLDER to read from a wider root, or --allow-outside-paths)
  grammar: ../above.lsys
           ^" ] || fail "an escape above a user species: $err"
(cd "$WORK" && sprig --root . check plants/above.yaml >/dev/null) || fail "--root widens the root"

# --- 3. one build for 11,111 aliased references -------------------------------------------
cp tests/bad_inputs/inputs/tiny_blob.yaml "$WORK/tiny.yaml"
{
  printf 'kind: solid\nsolid:\n  volume:\n    distance_field:\n      union:\n'
  printf '        - &a {species: {file: tiny.yaml}}\n'
  printf '        - &b {union: [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]}\n'
  printf '        - &c {union: [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]}\n'
  printf '        - &d {union: [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]}\n'
  printf '        - {union: [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]}\n'
  printf '    layers: [{interior_layer: {material: wood, thickness: fill}}]\n'
} >"$WORK/fanout.yaml"
start=$(date +%s)
timeout 60 "$SPRIG" --quiet check "$WORK/fanout.yaml" >/dev/null || fail "the aliased solid does not check within 60 s"
echo "cli_library_root: passed (aliased solid checked in $(($(date +%s) - start)) s)"
