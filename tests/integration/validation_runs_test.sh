#!/usr/bin/env bash
# scripts/validation_runs.sh + scripts/validation_table.py end to end, in miniature (validation
# seed 101 in its diverse scene at 32x32, 20 steps): two training seeds of the default and one of a
# variant, the table of the training-seed spread and of the variant against the default with the
# same seeds; a test identity (seed below 101) is refused before anything runs.
set -euo pipefail
ICEF="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

runs() { "$ROOT/scripts/validation_runs.sh" --icef "$ICEF" --out "$WORK/v" --seeds 101 --res 32 --steps 20 --threads 2 "$@"; }
runs --variant default --train-seeds "0 1" 2> "$WORK/log" || fail "default runs exited $?: $(cat "$WORK/log")"
runs --variant no-hull --set model.visual_hull.enabled=false --train-seeds 0 2>> "$WORK/log" || fail "variant exited $?"
for r in default_101_t0 default_101_t1 no-hull_101_t0; do
  test -s "$WORK/v/runs/$r/eval/metrics.json" || fail "no metrics for $r"
done
grep -q '"enabled": false' "$WORK/v/runs/no-hull_101_t0/config.json" || fail "the variant's --set did not reach its run"
test -s "$WORK/v/data/seed101_32/scene.json" || fail "the dataset is not the diverse scene"
# A finished run is kept, not trained again.
before=$(stat -c %Y "$WORK/v/runs/default_101_t0/eval/metrics.json")
runs --variant default --train-seeds 0 2> /dev/null
[ "$(stat -c %Y "$WORK/v/runs/default_101_t0/eval/metrics.json")" = "$before" ] || fail "a finished run was redone"

python3 "$ROOT/scripts/validation_table.py" "$WORK/v" > "$WORK/table.md" || fail "validation_table.py exited $?"
grep -Eq '^\| 101 \| [0-9.]+ / [0-9.]+ \| [0-9.]+ \|$' "$WORK/table.md" || fail "no spread row for 101: $(cat "$WORK/table.md")"
grep -q 'Suite mean over the 1 identities per training seed: seed 0: ' "$WORK/table.md" || fail "no per-seed suite mean"
grep -Eq '^\| no-hull \| 1 \| 101: [-+][0-9.]+ \|' "$WORK/table.md" || fail "no variant row: $(cat "$WORK/table.md")"

if runs --variant default --seeds 3 2> "$WORK/err"; then fail "a test identity was accepted"; fi
grep -q "seed 3 is a test identity" "$WORK/err" || fail "refusal message: $(cat "$WORK/err")"
[ ! -e "$WORK/v/data/seed3_32" ] || fail "a refused run wrote data"
echo "validation_runs_test: OK"
