#!/usr/bin/env python3
"""Sprig's species schema in an editor's language server (ctest `editor_yaml_language_server`).

Runs yaml-language-server (tools/yaml-language-server, installed by scripts/install-deps.sh)
over LSP on stdio, as VS Code's YAML extension and Neovim's yamlls do, with `sprig schema`
mapped to every file, and checks:
  1. every bad species of tests/editor/species/ gets, for each error `sprig check` reports,
     a diagnostic at the same line and column with the same gist: the kind of mistake
     (unknown key, wrong type, out of range, not one of the words, not a colour, missing
     key) and its subject (the unknown key's name, the bound that was crossed, the words
     allowed); and no diagnostic where `sprig check` reports none. The errors the schema
     cannot express (KNOWN_GAPS) must still be reported by `sprig check` alone;
  2. every shipped species (species/*.yaml) gets no diagnostic at all;
  3. a wrong colour reads as a colour's message, not "Incorrect type. Expected array";
  4. hovers show what a key does, with its range and default (a tree's `steps`, a
     render colour, a bark key, a solid's material entry and a key inside it).
Usage: tests/editor/run.py path/to/sprig   (run from the repository root)
"""
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lsp_client  # noqa: E402

SERVER = pathlib.Path("tools/yaml-language-server/node_modules/yaml-language-server/bin/yaml-language-server")
BAD = sorted(pathlib.Path("tests/editor/species").glob("*.yaml"))

# (file, line): errors `sprig check` finds that a JSON Schema cannot state, and why.
KNOWN_GAPS = {
    ("blob_nodes.yaml", 6): "a cone's radii are checked by the BlobTree builder, with the other radius and the offsets",
}


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


def gist_of_sprig(message):
    """(kind, subject) of one `sprig check` error message."""
    if m := re.match(r"unknown key '([^']+)'", message):
        return "unknown key", m.group(1)
    if m := re.match(r"unknown [a-z ]+ '[^']+'.*\(((?:one of: )?[\w, ]+)\)$", message):  # a one-key map's key
        return "not one of", ",".join(w for w in re.findall(r"\w+", m.group(1)) if w not in ("one", "of", "or"))
    if m := re.search(r"must be one of (.*), got", message):
        return "not one of", ",".join(w.strip() for w in m.group(1).split(","))
    if re.search(r"must be a colour", message):
        return "colour", ""
    if m := re.search(r"is (-?[\d.e+-]+), out of range \[([^,]+), ([^\]]+)\]", message):
        value, lo, hi = (float(x) for x in m.groups())
        return "range", repr(lo if value < lo else hi)
    if m := re.search(r"is (-?[\d.e+-]+), must be at (least|most) (\S+)", message):
        return "range", repr(float(m.group(3)))
    if re.search(r"must be positive", message):
        return "range", repr(0.0)
    if m := re.match(r"missing required key '([^']+)'", message):
        return "missing", m.group(1)
    if m := re.search(r"must be (an integer|true or false|a map|a sequence|\[x, y, z\]|a finite number|a number)", message):
        return "type", ""
    return "other", message


def gist_of_editor(message):
    """(kind, subject) of one yaml-language-server diagnostic."""
    if m := re.match(r"Property (\S+) is not allowed", message):
        return "unknown key", m.group(1)
    if m := re.match(r"Value is not accepted\. Valid values: (.*)\.$", message):
        return "not one of", ",".join(w.strip().strip('"') for w in m.group(1).split(","))
    if message.startswith("Expected a colour"):
        return "colour", ""
    if m := re.match(r"Value is (above|below) the (?:exclusive )?(maximum|minimum) of (\S+)\.$", message):
        return "range", repr(float(m.group(3)))
    if message.startswith("A colour's r, g and b"):
        return "range", "colour component"
    if m := re.match(r'Missing property "([^"]+)"', message):
        return "missing", m.group(1)
    if message.startswith("Incorrect type") or message.startswith("Array has too"):
        return "type", ""
    return "other", message


def sprig_errors(sprig, path):
    r = subprocess.run([sprig, "-q", "--root", ".", "check", str(path)], capture_output=True, text=True)
    if r.returncode != 1:
        fail("sprig check %s: exit %d, expected 1 (a bad file)" % (path, r.returncode))
    out = []
    for line in r.stderr.splitlines():
        if m := re.match(r"(.+?):(\d+):(\d+): error: (.*)", line):
            out.append((int(m.group(2)), int(m.group(3)), m.group(4)))
    if not out:
        fail("sprig check %s printed no error" % path)
    return out


def main():
    sprig = os.path.abspath(sys.argv[1])
    if not SERVER.exists():
        fail("yaml-language-server is not installed: run scripts/install-deps.sh")
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="sprig-editor-test-") as work:
        schema = os.path.join(work, "schema.json")
        subprocess.run([sprig, "-q", "schema", "-o", schema], check=True)
        shipped = sorted(pathlib.Path("species").glob("*.yaml"))
        if len(shipped) < 50:
            fail("only %d shipped species" % len(shipped))
        files = [str(p) for p in BAD + shipped]
        hovers = ["tests/editor/hover.yaml:2:2", "tests/editor/hover.yaml:5:4", "tests/editor/hover.yaml:8:6",
                  "tests/editor/hover_entries.yaml:3:4", "tests/editor/hover_entries.yaml:4:6"]
        diagnostics, texts = lsp_client.session(["node", str(SERVER)], schema,
                                                files + ["tests/editor/hover.yaml", "tests/editor/hover_entries.yaml"],
                                                hovers)

    # 1. The bad species: the same errors, line for line.
    compared = 0
    for path in BAD:
        want = {}
        for line, col, message in sprig_errors(sprig, path):
            want[(line, col)] = (gist_of_sprig(message), message)
        got = {}
        for line, col, message in diagnostics[str(path)]:
            got[(line, col)] = (gist_of_editor(message), message)
        for (line, col), (gist, message) in want.items():
            gap = KNOWN_GAPS.get((path.name, line))
            if gap:
                if (line, col) in got:
                    fail("%s:%d: the editor now reports '%s': remove it from KNOWN_GAPS" % (path, line, got[(line, col)][1]))
                continue
            if (line, col) not in got:
                fail("%s:%d:%d: sprig check says '%s'; the editor says nothing there (it says: %s)"
                     % (path, line, col, message, diagnostics[str(path)]))
            if got[(line, col)][0] != gist:
                fail("%s:%d:%d: sprig check says '%s' %s; the editor says '%s' %s"
                     % (path, line, col, message, gist, got[(line, col)][1], got[(line, col)][0]))
            compared += 1
        for (line, col), (gist, message) in got.items():
            if (line, col) not in want:
                fail("%s:%d:%d: the editor says '%s'; sprig check says nothing there" % (path, line, col, message))
    if compared < 25:
        fail("only %d errors compared" % compared)

    # 2. Every shipped species is clean in the editor as it is for sprig check.
    for p in shipped:
        if diagnostics[str(p)]:
            fail("%s: the editor reports %s" % (p, diagnostics[str(p)]))
    for hover_file in ("tests/editor/hover.yaml", "tests/editor/hover_entries.yaml"):
        if diagnostics[hover_file]:
            fail("%s: the editor reports %s" % (hover_file, diagnostics[hover_file]))

    # 3. A wrong colour reads as a colour.
    colour = [d[2] for d in diagnostics["tests/editor/species/tree_enums.yaml"] if d[0] == 10]
    if colour != ['Expected a colour: "#rrggbb" (six hex digits, sRGB) or [r, g, b] (linear, each from 0 to 1).']:
        fail("the message for 'leaf: \"5b3f28\"' is %s" % colour)

    # 4. Hovers: what the key does, then its range and default.
    wants = [("Derivation steps (default: the grammar's", "steps: an integer in [0, 100000]\n"),
             ("Preview colour of internodes", "default [0.3, 0.2, 0.12]"),
             ("Ridges around a branch", "an integer in [1, 1000]; default 9"),
             # inside a materials: entry, whose key (the material's name) the file chooses
             ("A material of this file, named by its key", "materials.NAME (material 'NAME'): a map"),
             ("Render roughness, 0 to 1.", "materials.NAME.roughness: a number in [0, 1]; default 0.5")]
    for text, (what, detail) in zip(texts, wants):
        text = re.sub(r"\\(.)", r"\1", text)  # the hover is Markdown: `\[0, 100000\]`
        if what not in text or detail not in text:
            fail("hover lacks '%s' or '%s': %r" % (what, detail, text))
    if len(texts) != len(wants):
        fail("%d hovers answered, %d asked" % (len(texts), len(wants)))
    print("editor: ok (%d errors of %d bad species agree with sprig check, %d known gaps, %d shipped species clean, "
          "%d hovers; %.1f s)" % (compared, len(BAD), len(KNOWN_GAPS), len(shipped), len(texts),
                                  time.monotonic() - start))


if __name__ == "__main__":
    main()
