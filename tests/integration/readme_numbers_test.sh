#!/usr/bin/env bash
# The README's benchmark summary quotes numbers; none may be typed by hand. Every decimal number
# between the README's bench-results markers must appear in the report it links
# (docs/results/bench/report.md, written by `icef bench`). Usage: readme_numbers_test.sh [ICEF]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
readme="$root/README.md"
report="$root/docs/results/bench/report.md"
section=$(sed -n '/<!-- bench-results:begin -->/,/<!-- bench-results:end -->/p' "$readme")
if [ -z "$section" ]; then
  echo "readme_numbers_test: README.md has no bench-results section" >&2
  exit 1
fi
grep -q "docs/results/bench/report.md" <<<"$section" || { echo "readme_numbers_test: section does not link the report" >&2; exit 1; }
[ -f "$report" ] || { echo "readme_numbers_test: $report missing" >&2; exit 1; }
missing=0
for n in $(grep -o -E '[0-9]+\.[0-9]+' <<<"$section" | sort -u); do
  if ! grep -q -F -- "$n" "$report"; then
    echo "readme_numbers_test: README quotes $n, which docs/results/bench/report.md does not contain" >&2
    missing=1
  fi
done
[ $missing -eq 0 ] && echo "readme_numbers_test: every number of the README's bench summary is in the report"
exit $missing
