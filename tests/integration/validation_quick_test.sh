#!/usr/bin/env bash
# icef bench --validation --quick end to end: the validation suite in miniature (validation seed
# 101, K = 5, methods icef and icef-prior, a tiny model for 20 steps at 32x32) on a diverse scene:
# the dataset records its drawn scene (scene.json), the report names the identities as validation
# identities, and each run's metrics carry the training-view fit.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

start=$SECONDS
"$ICEF" bench --validation --quick --out "$WORK/v" --threads 2 > "$WORK/v.txt" || fail "bench exited $?"
echo "validation --quick: $((SECONDS - start)) s"
S="$WORK/v/data/id101_k5/scene.json"
test -s "$S" || fail "no scene.json in the validation dataset"
grep -q '"drawn_axes": "skin,lighting,placement,camera,views,detail"' "$S" || fail "scene axes: $(grep drawn_axes "$S")"
grep -q "vary=skin,lighting,placement,camera,views,detail" "$WORK/v/data/id101_k5/synth_options.txt" \
  || fail "synth options do not record the drawn axes"
for r in id101_k5_icef id101_k5_icef-prior; do
  M="$WORK/v/runs/$r/metrics.json"
  test -s "$M" || fail "no metrics for $r"
  grep -q '"train_fit"' "$M" || fail "$r: metrics lack the training-view fit"
done
R="$WORK/v/report.md"
grep -q "validation identities" "$R" || fail "report does not name the identities as validation identities"
grep -q "diverse" "$R" || fail "report does not say the scenes are diverse"
echo "validation_quick_test: OK ($((SECONDS - start)) s)"
