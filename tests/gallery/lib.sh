# Sourced by the gallery's shell tests (run.sh, slurm_test.sh) after `set -euo pipefail`:
#   fail MESSAGE            prints "FAIL: MESSAGE" to stderr and exits 1
#   same_gallery A B        A and B hold the same files (manifests/ aside), byte for byte;
#                           index.html and pages/ compared without their timing cells
#   same_manifest_items A B the items of A's manifests equal those of B's (in any shard),
#                           the measured times (derive_seconds, render_seconds) aside
fail() { echo "FAIL: $*" >&2; exit 1; }

# The HTML without the text of its <td class="time"> cells (docs/GALLERY.md: measured timings).
_untimed_html() { sed 's|<td class="time">[^<]*</td>|<td class="time"></td>|g' "$1"; }

same_gallery() {
  local a=$1 b=$2
  diff <(cd "$a" && find . -type f ! -path './manifests/*' | sort) \
       <(cd "$b" && find . -type f ! -path './manifests/*' | sort) || fail "$a and $b hold different files"
  while read -r f; do
    if [ "$f" = ./index.html ] || [ "${f#./pages/}" != "$f" ]; then
      cmp -s <(_untimed_html "$a/$f") <(_untimed_html "$b/$f") || fail "$f differs"
    else
      cmp -s "$a/$f" "$b/$f" || fail "$f differs between $a and $b"
    fi
  done < <(cd "$a" && find . -type f ! -path './manifests/*' | sort)
}

# One line per item of every manifest in DIR/manifests, sorted, its timing fields (*_seconds) emptied.
# (A manifest writes one item per line: `{"source": ..., "outputs": [...]}`, a comma after all
# but the last.)
_manifest_items() {
  grep -h '^ *{"source": ' "$1"/manifests/*.json |
    sed -e 's/, *$//' -e 's/"\([a-z]*\)_seconds": [^,]*,/"\1_seconds": ,/g' |
    sort
}

same_manifest_items() {
  local a=$1 b=$2
  [ -n "$(_manifest_items "$a")" ] || fail "$a/manifests lists no item"
  diff <(_manifest_items "$a") <(_manifest_items "$b") || fail "the manifests of $a and $b list different items"
}
