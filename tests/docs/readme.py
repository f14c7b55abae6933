#!/usr/bin/env python3
"""The README's tutorial and links, checked against the repository.

  readme.py links ROOT FILE.md...      every relative link and #anchor resolves
  readme.py files ROOT README.md       every `<!-- tutorial: file PATH -->` block equals ROOT/PATH
  readme.py run ROOT README.md WORK [--blender]
                                       runs the `<!-- tutorial: run -->` blocks (and the
                                       `blender` ones with --blender) in WORK, in order, as
                                       written, and checks each `<!-- tutorial: expect -->`
                                       block against the output of the run block before it
  readme.py figures ROOT docs/FIGURES.md
                                       every paper-figure species (species/fig_*, blob_*)
                                       has a row, and every species a row names exists

Markers are HTML comments on the line before a fenced code block, so they do not show on a
rendered page. An expect block's lines must appear in that output in order, each as a whole
line; `...` in a line matches any text. Prints "FAIL: ..." and exits 1 on the first
problem of each check, listing every problem of that check.
"""
import os
import re
import subprocess
import sys
import unicodedata

MARKER = re.compile(r"^<!-- tutorial: (\w+)(?: (\S+))? -->$")


def blocks(path):
    """(kind, argument, text, line) for each marked fenced block of a markdown file."""
    lines = open(path, encoding="utf-8").read().split("\n")
    out = []
    i = 0
    while i < len(lines):
        m = MARKER.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        if j >= len(lines) or not lines[j].startswith("```"):
            sys.exit(f"FAIL: {path}:{i + 1}: a tutorial marker must stand right above a code block")
        k = j + 1
        while k < len(lines) and lines[k] != "```":
            k += 1
        if k >= len(lines):
            sys.exit(f"FAIL: {path}:{j + 1}: unclosed code block")
        out.append((m.group(1), m.group(2), "\n".join(lines[j + 1:k]) + "\n", j + 1))
        i = k + 1
    return out


def anchors(path):
    """The #anchors GitHub gives a markdown file's headings (fenced code skipped)."""
    seen = {}
    result = set()
    fence = False
    for line in open(path, encoding="utf-8"):
        if line.startswith("```"):
            fence = not fence
            continue
        if fence or not line.startswith("#"):
            continue
        m = re.match(r"^#{1,6} +(.*?) *#* *$", line.rstrip("\n"))
        if not m:
            continue
        text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", m.group(1)).lower()
        slug = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN").replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        result.add(slug if n == 0 else f"{slug}-{n}")
    return result


def check_links(root, files):
    problems = []
    link = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
    for f in files:
        fence = False
        for number, line in enumerate(open(f, encoding="utf-8"), 1):
            if line.startswith("```"):
                fence = not fence
            if fence:
                continue
            line = re.sub(r"`[^`]*`", "", line)  # code spans are not links
            for target in link.findall(line):
                if re.match(r"^[a-z]+:", target):
                    continue  # https:, mailto: ...
                path, _, anchor = target.partition("#")
                dest = os.path.normpath(os.path.join(os.path.dirname(f), path)) if path else f
                if not os.path.exists(dest):
                    problems.append(f"{f}:{number}: '{target}': no file {os.path.relpath(dest, root)}")
                elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                    problems.append(f"{f}:{number}: '{target}': no heading with anchor #{anchor} in {os.path.relpath(dest, root)}")
    return problems


def check_files(root, readme):
    problems = []
    for kind, arg, text, line in blocks(readme):
        if kind != "file":
            continue
        actual = open(os.path.join(root, arg), encoding="utf-8").read()
        if actual != text:
            problems.append(f"{readme}:{line}: the block differs from {arg} (copy the file into the README)")
    return problems


def expect(pattern_lines, output, where):
    """Each pattern line matches a whole output line, in order."""
    out_lines = output.split("\n")
    pos = 0
    for p in pattern_lines:
        if not p:
            continue
        rx = re.compile("^" + ".*".join(re.escape(part) for part in p.split("...")) + "$")
        while pos < len(out_lines) and not rx.match(out_lines[pos]):
            pos += 1
        if pos == len(out_lines):
            return f"{where}: expected a line '{p}' (in this order) in the output:\n{output}"
        pos += 1
    return None


def run(root, readme, work, blender):
    last_output = None
    ran = 0
    for kind, arg, text, line in blocks(readme):
        if kind == "run" or (kind == "blender" and blender):
            print(f"== {readme}:{line}\n{text}", end="", flush=True)
            p = subprocess.run(["bash", "-euo", "pipefail", "-c", text], cwd=work,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            last_output = p.stdout
            if p.returncode != 0:
                return [f"{readme}:{line}: the block failed (exit {p.returncode}):\n{p.stdout}"]
            ran += 1
        elif kind == "expect":
            if last_output is None:
                return [f"{readme}:{line}: an expect block with no run block before it"]
            problem = expect(text.split("\n"), last_output, f"{readme}:{line}")
            if problem:
                return [problem]
    if ran == 0:
        return [f"{readme}: no tutorial run blocks"]
    return []


FIGURE_SPECIES = re.compile(r"^(fig_|blob_).*\.yaml$")


def check_figures(root, table):
    """The figure table names every figure species, and only species that exist."""
    text = open(os.path.join(root, table), encoding="utf-8").read()
    rows = [line for line in text.splitlines() if line.startswith("| ")]
    named = set(re.findall(r"`([a-z][a-z0-9_]*)`", "\n".join(rows)))
    species = {f[:-5] for f in os.listdir(os.path.join(root, "species")) if FIGURE_SPECIES.match(f)}
    problems = [f"{table}: no row names species/{s}.yaml" for s in sorted(species - named)]
    problems += [f"{table}: `{n}` is not a species file" for n in sorted(named)
                 if not os.path.exists(os.path.join(root, "species", n + ".yaml"))]
    return problems


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    command, root = argv[1], argv[2]
    if command == "links":
        problems = check_links(root, argv[3:])
    elif command == "files":
        problems = check_files(root, argv[3])
    elif command == "figures":
        problems = check_figures(root, argv[3])
    elif command == "run":
        problems = run(root, argv[3], argv[4], "--blender" in argv[5:])
    else:
        sys.exit(__doc__)
    for p in problems:
        print("FAIL: " + p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
