#!/usr/bin/env bash
# Every relative link and image in README.md and docs/**/*.md must name a file (or folder) that
# exists in the tree: a clone must be able to follow what the docs point to. For each one that
# does not resolve it prints FILE:LINE and the link, and the test fails.
#
# Checked: inline links and images ([text](target), ![alt](target)) and reference definitions
# ([id]: target), outside fenced code blocks and inline code. A target is resolved against the
# directory of the file that holds it; the anchor after '#' is ignored, and so are absolute URLs
# (http:, https:, mailto:, ...) and links to an anchor of the same page.
# Usage: doc_links_test.sh [ICEF ...]   (the arguments are ignored: nothing is run)
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"

python3 - "$root" <<'PY'
import os, re, sys
from urllib.parse import unquote

root = sys.argv[1]
files = [os.path.join(root, "README.md")]
for d, _, names in os.walk(os.path.join(root, "docs")):
    files += [os.path.join(d, n) for n in names if n.endswith(".md")]

# [text](target "title") / ![alt](target): the target may hold one level of parentheses.
INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*(<[^>]*>|(?:[^()\s]|\([^()\s]*\))*)(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^ {0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
CODE = re.compile(r"(`+)(?:(?!\1).)+?\1")
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")

broken, checked = [], 0
for path in sorted(files):
    rel = os.path.relpath(path, root)
    fence = None
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for number, line in enumerate(lines, 1):
        m = re.match(r"^\s*(```+|~~~+)", line)
        if m:
            if fence is None:
                fence = m.group(1)[0] * 3
            elif m.group(1).startswith(fence):
                fence = None
            continue
        if fence is not None:
            continue
        text = CODE.sub("", line)
        targets = [t for t in INLINE.findall(text)]
        r = REFDEF.match(text)
        if r:
            targets.append(r.group(1))
        for target in targets:
            target = target.strip()
            if target.startswith("<") and target.endswith(">"):
                target = target[1:-1]
            if not target or target.startswith("#") or SCHEME.match(target):
                continue
            checked += 1
            file_part = unquote(target.split("#", 1)[0].split("?", 1)[0])
            base = root if file_part.startswith("/") else os.path.dirname(path)
            if not os.path.exists(os.path.normpath(os.path.join(base, file_part.lstrip("/")))):
                broken.append(f"{rel}:{number}: {target}")

for b in broken:
    print("doc_links_test: broken link", b, file=sys.stderr)
if broken:
    sys.exit(f"doc_links_test: {len(broken)} of {checked} relative links do not resolve")
if checked == 0:
    sys.exit("doc_links_test: no relative links found: is the parser broken?")
print(f"doc_links_test: {checked} relative links in {len(files)} Markdown files resolve")
PY
