#!/usr/bin/env python3
"""Point a Markdown file's bench section at another report and rewrite its table cells from it.

Usage: scripts/readme_bench_tables.py FILE.md docs/results/<bench>/report.json
  e.g. docs/results/README.md (the results page) or README.md (its headline table)

The first section between <!-- bench-results:begin REPORT --> and <!-- bench-results:end --> keeps
its rows (K, tier, method) and columns; every cell is rewritten as "mean ± std" (or "mean" where
the file shows no spread) of that (K, method, tier) cell of the new report's aggregate, with the
decimals the file used, and the section's links to the old bench directory are pointed at the
new one. REPORT is written relative to FILE.md's directory, as its links are.
tests/integration/readme_numbers_test.sh checks the result.
"""
import json
import os
import re
import sys


def fmt(value, decimals, signed):
    text = f"{value:.{decimals}f}"
    return ("+" + text) if signed and not text.startswith("-") else text


def rewrite_cell(text, spread):
    nums = re.findall(r"[-+]?\d+\.\d+", text)
    if not nums:
        return text
    decimals = len(nums[0].split(".")[1])
    signed = nums[0][0] in "+-"
    out = fmt(spread["mean"], decimals, signed)
    if len(nums) > 1:
        out += " ± " + fmt(spread["std"], len(nums[1].split(".")[1]), False)
    return out


def main(readme_path, report_path):
    readme = open(readme_path).read()
    m = re.search(r"<!-- bench-results:begin (\S+) -->(.*?)<!-- bench-results:end -->", readme, re.S)
    if not m:
        sys.exit(f"{readme_path}: no bench-results section")
    old_report, section = m.group(1), m.group(2)
    report = json.load(open(report_path))
    cells = {(c["k"], c["method"], c["tier"]): c for c in report["aggregate"]}
    header, lines = None, []
    for line in section.split("\n"):
        s = line.strip()
        cols = [c.strip() for c in s.strip("|").split("|")] if s.startswith("|") else None
        if cols and cols[:3] == ["K", "tier", "method"]:
            header = cols
        elif cols and header and not set(s) <= set("|-: "):
            key = (int(cols[0]), cols[2].strip("`"), cols[1])
            if key not in cells:
                sys.exit(f"{report_path}: no aggregate cell for K={key[0]} {key[2]} {key[1]}")
            cols = cols[:3] + [rewrite_cell(t, cells[key][h]) for h, t in zip(header[3:], cols[3:])]
            line = line[: len(line) - len(line.lstrip())] + "| " + " | ".join(cols) + " |"
        lines.append(line)
    new_report = os.path.relpath(report_path, os.path.dirname(os.path.abspath(readme_path)))
    old_dir, new_dir = os.path.dirname(old_report), os.path.dirname(new_report)
    section = "\n".join(lines).replace(old_dir + "/", new_dir + "/")
    out = readme[: m.start()] + f"<!-- bench-results:begin {new_report} -->" + section + "<!-- bench-results:end -->"
    out += readme[m.end():]
    with open(readme_path + ".tmp", "w") as f:
        f.write(out)
    os.replace(readme_path + ".tmp", readme_path)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
