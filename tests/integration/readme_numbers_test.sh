#!/usr/bin/env bash
# The measured figures in the docs quote numbers; none may be typed by hand. Two files are checked:
# docs/results/README.md (the results page: the benches and the training curve) and README.md (its
# headline table). Each must have at least one bench section; the results page also the curve.
#
# Benches: each section between <!-- bench-results:begin REPORT --> and <!-- bench-results:end -->
# names the report.json it summarises, as a path relative to the Markdown file, and must link the
# report.md beside it. Its tables have columns K, tier, method and then metric keys of report.json
# (psnr, expr_gain, id_distance_gt, ...), or K, method and then keys of the report's training-view
# fit (face_psnr, face_psnr_min, psnr); every cell "mean", "mean ± std", "mean [min, max]" or
# "mean ± std [min, max]" must equal that cell of the report's aggregate (train_fit), rounded to the
# decimals shown. A decimal number anywhere else in a section is an error: numbers live in checked
# tables. At least 10 numbers per section must be checked.
# Training curve: every row "| step | seconds | PSNR |" between <!-- train-curve:begin LOG.jsonl -->
# (a path relative to the Markdown file) and <!-- train-curve:end --> must be a line of that
# committed training log (seconds to 0 and PSNR to 2 decimals).
# scripts/readme_bench_tables.py rewrites a bench section's cells from another report.
# Usage: readme_numbers_test.sh [ICEF ...]   (the arguments are ignored: nothing is run)
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
results="$root/docs/results/README.md"

for doc in "$results" "$root/README.md"; do
python3 - "$root" "$doc" <<'PY'
import json, os, re, sys
root, doc_path = sys.argv[1], sys.argv[2]
doc, base, name_of_doc = open(doc_path).read(), os.path.dirname(doc_path), os.path.relpath(doc_path, root)
sections = re.findall(r"<!-- bench-results:begin (\S+) -->(.*?)<!-- bench-results:end -->", doc, re.S)
if not sections:
    sys.exit(f"readme_numbers_test: {name_of_doc} has no '<!-- bench-results:begin REPORT.json -->' section")
NUM = r"[-+]?\d+(?:\.\d+)?"
CELL = re.compile(rf"^({NUM})(?:\s*±\s*({NUM}))?(?:\s*\[({NUM}),\s*({NUM})\])?$")

def decimals(text):
    return len(text.split(".")[1]) if "." in text else 0

errors = []
for report_path, section in sections:
    if not os.path.isfile(os.path.join(base, report_path)):
        errors.append(f"{report_path}: no such file (paths are relative to {name_of_doc})")
        continue
    report = json.load(open(os.path.join(base, report_path)))
    if report_path.replace("report.json", "report.md") not in section:
        errors.append(f"the section of {report_path} does not link {report_path.replace('report.json', 'report.md')}")
    tiers = {(c["k"], c["method"], c["tier"]): c for c in report["aggregate"]}
    fits = {(c["k"], c["method"]): c for c in report.get("train_fit", [])}
    checked, header, keyed, errors_before = 0, None, 0, len(errors)
    outside = []
    for line in section.splitlines():
        s = line.strip()
        if not s.startswith("|"):
            outside.append(line)
            continue
        cols = [c.strip() for c in s.strip("|").split("|")]
        if cols[:3] == ["K", "tier", "method"] or cols[:2] == ["K", "method"]:
            header, keyed = cols, 3 if cols[1] == "tier" else 2
            continue
        if header is None or set(s) <= set("|-: "):
            continue
        k, method = int(cols[0]), cols[keyed - 1].strip("`")
        name = f"K={k} {cols[1] + ' ' if keyed == 3 else ''}{method}"
        cell = tiers.get((k, method, cols[1])) if keyed == 3 else fits.get((k, method))
        if cell is None:
            errors.append(f"{report_path}: row {name}: no such cell")
            continue
        for key, text in zip(header[keyed:], cols[keyed:]):
            spread = cell.get(key)
            m = CELL.match(text)
            if spread is None or not m:
                errors.append(f"{report_path}: row {name}: {key} '{text}' has no value in the report")
                continue
            for value, stat in zip(m.groups(), ["mean", "std", "min", "max"]):
                if value is None:
                    continue
                want = f"{spread[stat]:.{decimals(value)}f}"
                if float(value) != float(want):
                    errors.append(f"{report_path}: row {name}: {key} {stat} is {value} in {name_of_doc}, {want} in the report")
                checked += 1
    for line in outside:
        for n in re.findall(r"\d+\.\d+", line):
            errors.append(f"{report_path}: a number outside the checked tables: {n} in '{line.strip()}'")
    if checked < 10:
        errors.append(f"only {checked} numbers checked against {report_path}: is the table there?")
    elif len(errors) == errors_before:
        print(f"readme_numbers_test: {checked} numbers of {name_of_doc} match {report_path} cell by cell")
for e in errors:
    print(f"readme_numbers_test: {name_of_doc}:", e, file=sys.stderr)
if errors:
    sys.exit(1)
PY
done

# The results page's training curve.
log_rel=$(sed -nE 's/.*<!-- train-curve:begin ([^ ]+) -->.*/\1/p' "$results" | head -n 1)
if [ -z "$log_rel" ] || [ ! -f "$(dirname "$results")/$log_rel" ]; then
  echo "readme_numbers_test: docs/results/README.md has no '<!-- train-curve:begin LOG.jsonl -->' naming a committed log ('$log_rel')" >&2
  exit 1
fi
log="$(dirname "$results")/$log_rel"
missing=0
rows=$(sed -n '/<!-- train-curve:begin /,/<!-- train-curve:end -->/p' "$results" | grep -E '^ *\| [0-9]+ \|' || true)
if [ -z "$rows" ]; then
  echo "readme_numbers_test: docs/results/README.md has no train-curve rows" >&2
  missing=1
fi
while read -r step secs psnr; do
  line=$(grep -E "^\{\"step\":$step," "$log" || true)
  got_secs=$(sed -E 's/.*"seconds":([0-9.eE+-]+).*/\1/' <<<"$line")
  got_psnr=$(sed -nE 's/.*"psnr_observed":([0-9.eE+-]+).*/\1/p' <<<"$line")
  if [ -z "$line" ] || [ -z "$got_psnr" ] || [ "$(printf '%.0f' "$got_secs")" != "$secs" ] ||
     [ "$(printf '%.2f' "$got_psnr")" != "$psnr" ]; then
    echo "readme_numbers_test: docs/results/README.md curve row step $step ($secs s, $psnr dB) is not in $log" >&2
    missing=1
  fi
done < <(awk -F'|' '{gsub(/ /, "", $2); gsub(/ /, "", $3); gsub(/ /, "", $4); print $2, $3, $4}' <<<"$rows")
[ $missing -eq 0 ] && echo "readme_numbers_test: the training curve of docs/results/README.md matches $log_rel"

# Real media: each table between <!-- real-results:begin REPORT.json --> and <!-- real-results:end -->
# (icef bench --real's report.json, a path relative to the Markdown file) has columns source, K,
# method, then keys of a run's means (face_psnr, face_psnr_nearest, real_expr_gain, ...); every
# cell must equal that run's mean, rounded to the decimals shown.
for doc in "$results" "$root/README.md"; do
python3 - "$root" "$doc" <<'PY' || missing=1
import json, os, re, sys
root, doc_path = sys.argv[1], sys.argv[2]
doc, base, name = open(doc_path).read(), os.path.dirname(doc_path), os.path.relpath(doc_path, root)
errors, checked = [], 0
for report_path, section in re.findall(r"<!-- real-results:begin (\S+) -->(.*?)<!-- real-results:end -->", doc, re.S):
    runs = {(r["source"], r["k"], r["method"]): r for r in json.load(open(os.path.join(base, report_path)))["runs"]}
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in section.splitlines() if line.startswith("|")]
    header, body = rows[0], [r for r in rows[2:]]
    if header[:3] != ["source", "K", "method"]:
        errors.append(f"{name}: real-results table must start with source | K | method, got {header[:3]}")
        continue
    for row in body:
        key = (row[0], int(row[1]), row[2].strip("`"))
        if key not in runs:
            errors.append(f"{name}: {key} is not a run of {report_path}")
            continue
        for col, cell in zip(header[3:], row[3:]):
            want = runs[key]["metrics"]["means"][col.strip("`")]
            digits = len(cell.split(".")[1]) if "." in cell else 0
            if want is None or f"{want:.{digits}f}" != cell:
                errors.append(f"{name}: {key} {col}: the table says {cell}, {report_path} has {want}")
            checked += 1
for e in errors:
    print("readme_numbers_test:", e, file=sys.stderr)
if checked and not errors:
    print(f"readme_numbers_test: {checked} real-media numbers of {name} match their report")
sys.exit(1 if errors else 0)
PY
done
exit $missing
