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

# The README's training curve: every row "| step | seconds | PSNR |" between the train-curve markers
# must be a line of docs/results/train_k5_128_icef.jsonl (seconds to 0 and PSNR to 2 decimals).
log="$root/docs/results/train_k5_128_icef.jsonl"
rows=$(sed -n '/<!-- train-curve:begin -->/,/<!-- train-curve:end -->/p' "$readme" | grep -E '^ *\| [0-9]+ \|' || true)
if [ -z "$rows" ]; then
  echo "readme_numbers_test: README.md has no train-curve rows" >&2
  missing=1
fi
while read -r step secs psnr; do
  line=$(grep -E "^\{\"step\":$step," "$log" || true)
  got_secs=$(sed -E 's/.*"seconds":([0-9.eE+-]+).*/\1/' <<<"$line")
  got_psnr=$(sed -nE 's/.*"psnr_observed":([0-9.eE+-]+).*/\1/p' <<<"$line")
  if [ -z "$line" ] || [ -z "$got_psnr" ] || [ "$(printf '%.0f' "$got_secs")" != "$secs" ] ||
     [ "$(printf '%.2f' "$got_psnr")" != "$psnr" ]; then
    echo "readme_numbers_test: README curve row step $step ($secs s, $psnr dB) is not in $log" >&2
    missing=1
  fi
done < <(awk -F'|' '{gsub(/ /, "", $2); gsub(/ /, "", $3); gsub(/ /, "", $4); print $2, $3, $4}' <<<"$rows")
[ $missing -eq 0 ] && echo "readme_numbers_test: the README's training curve matches the committed log"
exit $missing
