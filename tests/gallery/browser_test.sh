#!/usr/bin/env bash
# The gallery as people browse it (registered with ctest as `gallery_browser`), on a small
# gallery of three species of two kinds:
#   1. index.html groups the species by kind, every card links to its page, and every
#      page and image it names exists; each species has a page with its still, strip and
#      animation and a 320x240 thumbnail;
#   2. the animation's first frame is the grown form (the last frame), not the sprout;
#   3. headless Chromium loads the index and every page: every image loads (complete,
#      naturalWidth > 0), the filter box narrows the grid, and no page logs a console
#      message (errors included); a screenshot of the index is written and is not blank.
# Usage: tests/gallery/browser_test.sh path/to/sprig [SCREENSHOT.png]   (run from the repository root)
set -euo pipefail
SPRIG=$(realpath "$1")
SHOT=${2:-}
SRC=$(pwd)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sprig-gallery-browser-XXXXXX")
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v chromium >/dev/null || fail "chromium is not installed (scripts/install-deps.sh installs it)"

mkdir -p "$WORK/lib/species" "$WORK/lib/grammars"
cp "$SRC"/tests/gallery/species/edge.yaml "$SRC"/tests/gallery/species/shrub.yaml "$WORK/lib/species/"
cp "$SRC"/grammars/abop_1_24a.lsys "$SRC"/grammars/shrub.lsys "$WORK/lib/grammars/"
cp "$SRC"/tests/gallery/blob_ball.yaml "$WORK/lib/species/"
cd "$WORK/lib"
"$SPRIG" --root . --threads 2 -q gallery species/*.yaml -o out 2> log || { cat log; fail "gallery failed"; }

# --- 1. files and links -------------------------------------------------------------------
for s in edge shrub blob_ball; do
  for f in "$s.png" "${s}_stages.png" "$s.gif" "thumbs/$s.png" "pages/$s.html"; do
    [ -s "out/$f" ] || fail "out/$f missing"
  done
done
/usr/bin/python3 - out <<'PY' || fail "index or pages name a missing file"
import os, re, sys
out = sys.argv[1]
index = open(os.path.join(out, "index.html")).read()
sections = re.findall(r'<section id="kind-([a-z]+)">\s*<h2>([^<]*)</h2>', index)
assert sections == [("tree", "Trees"), ("blob", "BlobTree models")], sections
cards = re.findall(r'<a class="card" href="([^"]+)"', index)
assert sorted(cards) == ["pages/blob_ball.html", "pages/edge.html", "pages/shrub.html"], cards
for page in ["index.html"] + cards:
    text = open(os.path.join(out, page)).read()
    base = os.path.dirname(os.path.join(out, page))
    for ref in re.findall(r'(?:src|href)="([^"#:]+)"', text):
        assert os.path.isfile(os.path.normpath(os.path.join(base, ref))), (page, ref)
    if page != "index.html":
        imgs = re.findall(r'<img src="([^"]+)"', text)
        assert len(imgs) == 3, (page, imgs)   # still, strip, animation
PY
[ "$(oiiotool --info -v out/thumbs/edge.png | grep -c '320 x  240')" -eq 1 ] || fail "thumbnail is not 320x240"

# --- 2. the animation opens on the grown form --------------------------------------------
n=$(oiiotool --info out/edge.gif | grep -oE '[0-9]+ subimages' | grep -oE '[0-9]+' || true)
[ "${n:-0}" -gt 2 ] || fail "edge.gif has $n frames"
oiiotool out/edge.gif --subimage 0 -o first.png
oiiotool out/edge.gif --subimage $((n - 1)) -o last.png
oiiotool out/edge.gif --subimage $((n / 2)) -o middle.png
# Each GIF frame has its own 256-colour palette, so equal renders differ by a few levels.
idiff -fail 0.03 -warn 0.03 first.png last.png >/dev/null || fail "the animation's first frame is not the grown form (its last frame)"
! idiff -fail 0.03 -warn 0.03 first.png middle.png >/dev/null 2>&1 || fail "the animation does not grow (first and middle frames alike)"

# --- 3. headless Chromium ----------------------------------------------------------------
cat > check.html <<'HTML'
<!DOCTYPE html><html><body><pre id="result">running</pre><script>
const pages = ['out/index.html', 'out/pages/edge.html', 'out/pages/shrub.html', 'out/pages/blob_ball.html'];
const lines = [];
function load(src) {
  return new Promise(done => {
    const f = document.createElement('iframe');
    f.style.width = '1200px'; f.style.height = '900px';
    f.onload = () => done(f);
    f.src = src;
    document.body.appendChild(f);
  });
}
function imagesLoaded(doc) {
  return Promise.all([...doc.images].map(img => img.complete ? Promise.resolve() :
    new Promise(r => { img.onload = r; img.onerror = r; })));
}
(async () => {
  for (const p of pages) {
    const f = await load(p);
    const doc = f.contentDocument;
    if (!doc) { lines.push(p + ' NOACCESS'); continue; }
    await imagesLoaded(doc);
    const imgs = [...doc.images];
    const bad = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute('src'));
    lines.push(p + ' images=' + imgs.length + ' broken=' + bad.length + (bad.length ? ' ' + bad.join(',') : ''));
    if (p.endsWith('index.html')) {
      const box = doc.getElementById('filter');
      const visible = () => [...doc.querySelectorAll('.card')].filter(c => !c.hidden && !c.closest('section').hidden).length;
      const all = visible();
      box.value = 'shrub'; box.dispatchEvent(new Event('input'));
      const one = visible();
      box.value = 'blobtree'; box.dispatchEvent(new Event('input'));
      const blobs = visible();
      box.value = 'no such species'; box.dispatchEvent(new Event('input'));
      const none = visible();
      lines.push('filter all=' + all + ' shrub=' + one + ' blobtree=' + blobs + ' none=' + none +
                 ' count=' + doc.getElementById('count').textContent);
    }
  }
  document.getElementById('result').textContent = lines.join('\n') + '\ndone';
})();
</script></body></html>
HTML
chrome() {
  timeout 120 chromium --headless --no-sandbox --disable-gpu --allow-file-access-from-files --no-first-run \
    --disable-extensions --enable-logging=stderr --v=0 "$@"
}
chrome --virtual-time-budget=10000 --dump-dom "file://$PWD/check.html" > dom.html 2> chrome.log || true
result=$(sed -n '/<pre id="result">/,/<\/pre>/p' dom.html | sed 's/<[^>]*>//g')
echo "$result"
echo "$result" | grep -qx "done" || { cat chrome.log; fail "the check page did not finish"; }
expected="out/index.html images=3 broken=0
filter all=3 shrub=1 blobtree=1 none=0 count=0 of 3 species
out/pages/edge.html images=3 broken=0
out/pages/shrub.html images=3 broken=0
out/pages/blob_ball.html images=3 broken=0
done"
[ "$result" = "$expected" ] || fail "unexpected browser results"
if grep -E 'CONSOLE|Uncaught|ERR_FILE_NOT_FOUND|Not allowed to load' chrome.log; then
  fail "the gallery logged console messages or failed loads"
fi
shot=${SHOT:-$PWD/shot.png}
chrome --window-size=1280,900 --hide-scrollbars --screenshot="$shot" "file://$PWD/out/index.html" 2> shot.log || true
[ -s "$shot" ] || { cat shot.log; fail "no screenshot"; }
grep -E 'CONSOLE|Uncaught' shot.log && fail "the index logged console messages"
# Not blank: the screenshot has many distinct colours (thumbnails), not just the page's few.
oiiotool "$shot" -d uint8 -o shot.ppm
colours=$(/usr/bin/python3 -c '
import sys
data = open(sys.argv[1], "rb").read()
parts = data.split(maxsplit=4)          # P6, width, height, maxval, pixels
px = parts[4]
print(len({px[i:i + 3] for i in range(0, len(px) - 2, 3)}))' shot.ppm)
[ "${colours:-0}" -gt 500 ] || fail "the screenshot looks blank ($colours colours)"
echo "gallery browser: ok ($colours colours in the screenshot)"
