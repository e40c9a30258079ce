#!/usr/bin/env bash
# icef bench --quick end to end (tiny settings: 1 identity, K = 3, all five methods, 32x32, a tiny
# model for 20 steps), run as two shards and merged: checks the per-run metrics, the report
# (verdict computed, stand-in caveat, tables), report.json, the plots (when gnuplot is installed),
# that finished runs are skipped, and that the unsharded bench over all runs gives the same verdict.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
RUNS=(id1_k3_icef id1_k3_icef-no-id id1_k3_icef-no-conf id1_k3_warp id1_k3_nerface)

start=$SECONDS
"$ICEF" bench --quick --out "$WORK/a" --shard 0/2 --threads 2 > "$WORK/a.txt" || fail "shard 0/2 exited $?"
"$ICEF" bench --quick --out "$WORK/b" --shard 1/2 --threads 2 > "$WORK/b.txt" || fail "shard 1/2 exited $?"
echo "two shards: $((SECONDS - start)) s"
grep -q "bench: 3 runs in shard 0/2 (0 already done)" "$WORK/a.txt" || fail "shard 0/2 plan: $(head -1 "$WORK/a.txt")"
grep -q "bench: 2 runs in shard 1/2 (0 already done)" "$WORK/b.txt" || fail "shard 1/2 plan: $(head -1 "$WORK/b.txt")"
for r in id1_k3_icef id1_k3_icef-no-conf id1_k3_nerface; do test -s "$WORK/a/runs/$r/metrics.json" || fail "a: $r"; done
for r in id1_k3_icef-no-id id1_k3_warp; do test -s "$WORK/b/runs/$r/metrics.json" || fail "b: $r"; done
test ! -e "$WORK/a/runs/id1_k3_icef/model" || fail "model kept without --keep-models"
grep -q "Shard 0/2 only" "$WORK/a/report.md" || fail "shard report lacks the shard note"

"$ICEF" bench merge "$WORK/a" "$WORK/b" --out "$WORK/m" > "$WORK/m.txt" || fail "merge exited $?"
cat "$WORK/m.txt"
for r in "${RUNS[@]}"; do test -s "$WORK/m/runs/$r/metrics.json" || fail "merged: $r"; done
grep -q "bench merge: 5 runs" "$WORK/m.txt" || fail "merge count"
R="$WORK/m/report.md"
grep -q "## Verdict (far tier, computed)" "$R" || fail "no verdict"
grep -Eq "\*\*Identity similarity\*\* \(id_distance.*K=3 vs warp: (better|not better)" "$R" || fail "no identity verdict"
grep -Eq "\*\*PSNR\*\* .*K=3 vs nerface: (better|not better)" "$R" || fail "no PSNR verdict"
grep -q "FDNeRF and NeRFFaceEditing proper are not available" "$R" || fail "no stand-in caveat"
grep -q "^| far | \`icef\` | 1 |" "$R" || fail "no far-tier icef row"
[ "$(grep -c '^| observed | ' "$R")" = 5 ] || fail "expected 5 observed rows"
python3 - "$WORK/m/report.json" <<'PY' || fail "report.json"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["ks"] == [3] and r["identities"] == [1], (r["ks"], r["identities"])
assert r["methods"] == ["icef", "icef-no-id", "icef-no-conf", "warp", "nerface"], r["methods"]
assert len(r["runs"]) == 5 and len(r["aggregate"]) == 5 * 4
for c in r["aggregate"]:
    if c["runs"] > 0:
        assert c["psnr"]["n"] == 1 and c["psnr"]["std"] == 0
assert any(c["metric"] == "id_distance" and c["other"] == "warp" for c in r["far_comparisons"])
assert len(r["verdict"]) == 3
PY
if command -v gnuplot > /dev/null; then
  for p in psnr ssim id_distance id_cosine; do
    test -s "$WORK/m/plots/$p.png" || fail "no $p.png"
    test -s "$WORK/m/plots/$p.svg" || fail "no $p.svg"
  done
  grep -q "!\[plots/psnr.png\](plots/psnr.png)" "$R" || fail "report does not show the plots"
fi

# Resume: a finished run is skipped (nothing is trained again).
"$ICEF" bench --quick --out "$WORK/a" --shard 0/2 --threads 2 > "$WORK/a2.txt" || fail "resume exited $?"
grep -q "bench: 3 runs in shard 0/2 (3 already done)" "$WORK/a2.txt" || fail "resume plan: $(head -1 "$WORK/a2.txt")"
if grep -q "^train " "$WORK/a2.txt"; then fail "a finished run was trained again"; fi
# The unsharded bench over a directory holding every run only writes the report, and its verdict
# is the merged one.
mkdir -p "$WORK/c" && cp -r "$WORK/m/runs" "$WORK/c/"
"$ICEF" bench --quick --out "$WORK/c" --threads 2 > "$WORK/c.txt" || fail "unsharded bench exited $?"
grep -q "bench: 5 runs in shard 0/1 (5 already done)" "$WORK/c.txt" || fail "unsharded plan: $(head -1 "$WORK/c.txt")"
diff <(grep -A4 "^## Verdict" "$WORK/c/report.md") <(grep -A4 "^## Verdict" "$R") || fail "verdicts differ"

# Bad options exit 1 with a message.
if "$ICEF" bench --out "$WORK/x" --shard 2/2 2> "$WORK/err.txt"; then fail "bad shard accepted"; fi
grep -q "shard" "$WORK/err.txt" || fail "unclear shard error"
if "$ICEF" bench --out "$WORK/x" --methods icef,fdnerf 2> "$WORK/err.txt"; then fail "unknown method accepted"; fi
grep -q "fdnerf" "$WORK/err.txt" || fail "unclear method error"
echo "bench_quick_test: OK ($((SECONDS - start)) s)"
