#!/usr/bin/env bash
# icef bench --quick end to end (tiny settings: 1 identity, K = 3, all seven methods, 32x32, a tiny
# model for 20 steps), run as two shards and merged: checks the per-run metrics, the report
# (verdict computed, stand-in caveat, tables), report.json, the plots (when gnuplot is installed),
# that finished runs are skipped, and that the unsharded bench over all runs gives the same verdict.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
RUNS=(id1_k3_icef-prior id1_k3_warp-prior id1_k3_icef id1_k3_icef-no-conf id1_k3_icef-uniform id1_k3_warp id1_k3_nerface)

start=$SECONDS
"$ICEF" bench --quick --out "$WORK/a" --shard 0/2 --threads 2 > "$WORK/a.txt" || fail "shard 0/2 exited $?"
"$ICEF" bench --quick --out "$WORK/b" --shard 1/2 --threads 2 > "$WORK/b.txt" || fail "shard 1/2 exited $?"
echo "two shards: $((SECONDS - start)) s"
grep -q "bench: 4 runs in shard 0/2 (0 already done)" "$WORK/a.txt" || fail "shard 0/2 plan: $(head -1 "$WORK/a.txt")"
grep -q "bench: 3 runs in shard 1/2 (0 already done)" "$WORK/b.txt" || fail "shard 1/2 plan: $(head -1 "$WORK/b.txt")"
for r in id1_k3_icef-prior id1_k3_icef id1_k3_icef-uniform id1_k3_nerface; do test -s "$WORK/a/runs/$r/metrics.json" || fail "a: $r"; done
for r in id1_k3_warp-prior id1_k3_icef-no-conf id1_k3_warp; do test -s "$WORK/b/runs/$r/metrics.json" || fail "b: $r"; done
test ! -e "$WORK/a/runs/id1_k3_icef/model" || fail "model kept without --keep-models"
grep -q "Shard 0/2 only" "$WORK/a/report.md" || fail "shard report lacks the shard note"

"$ICEF" bench merge "$WORK/a" "$WORK/b" --out "$WORK/m" > "$WORK/m.txt" || fail "merge exited $?"
cat "$WORK/m.txt"
for r in "${RUNS[@]}"; do test -s "$WORK/m/runs/$r/metrics.json" || fail "merged: $r"; done
grep -q "bench merge: 7 runs" "$WORK/m.txt" || fail "merge count"
R="$WORK/m/report.md"
grep -q "## Verdict (computed)" "$R" || fail "no verdict"
grep -q "a method is better than another in a tier only where it reproduces at least 10% of the expression" "$R" \
  || fail "no verdict rule"
outcome="(better|under-expresses|not better on identity|not better on PSNR)"
grep -Eq "\*\*far tier, icef vs the baselines\*\*: .*K=3 vs warp: $outcome" "$R" || fail "no far-tier verdict vs warp"
grep -Eq "\*\*far tier, icef vs the baselines\*\*: .*K=3 vs nerface: $outcome" "$R" || fail "no far-tier verdict vs nerface"
grep -Eq "\*\*far tier, icef-prior vs every other method\*\*: .*K=3 vs icef: $outcome" "$R" \
  || fail "no far-tier verdict of icef-prior vs icef"
grep -q "\*\*Expression reproduced, K=3\*\*" "$R" || fail "no expression line"
grep -q "tiers by delta: observed = 0, near (0, 0.35]" "$R" || fail "no tier thresholds"
grep -q "identities (seeds): 1 (test identities" "$R" || fail "identities not named as test identities"
grep -q "FDNeRF and NeRFFaceEditing proper are not available" "$R" || fail "no stand-in caveat"
T="$WORK/m/report.tex"
grep -q "label{tab:icef-bench-k3}" "$T" || fail "report.tex lacks the K = 3 table"
grep -q "label{tab:icef-bench-far}" "$T" || fail "report.tex lacks the far-tier table"
for m in icef-prior warp-prior icef icef-no-conf icef-uniform warp nerface; do
  grep -q "texttt{$m}" "$T" || fail "report.tex lacks $m"
done
if command -v pdflatex > /dev/null && kpsewhich booktabs.sty > /dev/null; then  # not installed by the setup
  mkdir "$WORK/tex"
  printf '\\documentclass{article}\n\\usepackage{booktabs}\n\\begin{document}\n\\input{%s}\n\\end{document}\n' "$T" > "$WORK/tex/main.tex"
  (cd "$WORK/tex" && pdflatex -interaction=nonstopmode -halt-on-error main.tex > latex.log 2>&1) \
    || fail "report.tex does not compile: $(grep -A3 '^!' "$WORK/tex/latex.log")"
  echo "report.tex compiles with pdflatex"
fi
grep -q "^| far | \`icef\` | 1 |" "$R" || fail "no far-tier icef row"
[ "$(grep -c '^| observed | ' "$R")" = 14 ] || fail "expected 14 observed rows (7 methods, 2 tables)"
python3 - "$WORK/m/report.json" <<'PY' || fail "report.json"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["ks"] == [3] and r["identities"] == [1], (r["ks"], r["identities"])
assert r["methods"] == ["icef", "icef-no-conf", "icef-uniform", "warp", "nerface", "icef-prior", "warp-prior"], r["methods"]
assert len(r["runs"]) == 7 and len(r["aggregate"]) == 7 * 4
for c in r["aggregate"]:
    if c["runs"] > 0:
        assert c["psnr"]["n"] == 1 and c["psnr"]["std"] == 0
assert any(c["metric"] == "id_distance" and c["other"] == "warp" for c in r["far_comparisons"])
assert len(r["verdict"]) >= 3, r["verdict"]
assert {v["other"] for v in r["pair_verdicts"] if v["method"] == "icef"} == {
    "icef-prior", "warp-prior", "icef-no-conf", "icef-uniform", "warp", "nerface"}
assert {v["other"] for v in r["pair_verdicts"] if v["method"] == "icef-prior"} == {
    "warp-prior", "icef", "icef-no-conf", "icef-uniform", "warp", "nerface"}
assert r["tier_thresholds"] == [0.35, 0.8]
far = [c for c in r["aggregate"] if c["tier"] == "far" and c["method"] == "icef"][0]
for k in ["expr_gain", "expr_corr", "region_psnr", "psnr_neutral_floor", "id_distance_gt"]:
    assert far[k] is not None, k
PY
if command -v gnuplot > /dev/null; then
  for p in psnr ssim expr_gain region_psnr id_distance id_cosine; do
    test -s "$WORK/m/plots/$p.png" || fail "no $p.png"
    test -s "$WORK/m/plots/$p.svg" || fail "no $p.svg"
    test -s "$WORK/m/plots/$p.pdf" || fail "no $p.pdf"
  done
  grep -q "!\[plots/psnr.png\](plots/psnr.png)" "$R" || fail "report does not show the plots"
fi

# Resume: a finished run is skipped (nothing is trained again).
"$ICEF" bench --quick --out "$WORK/a" --shard 0/2 --threads 2 > "$WORK/a2.txt" || fail "resume exited $?"
grep -q "bench: 4 runs in shard 0/2 (4 already done)" "$WORK/a2.txt" || fail "resume plan: $(head -1 "$WORK/a2.txt")"
if grep -q "^train " "$WORK/a2.txt"; then fail "a finished run was trained again"; fi
# The unsharded bench over a directory holding every run only writes the report, and its verdict
# is the merged one.
mkdir -p "$WORK/c" && cp -r "$WORK/m/runs" "$WORK/c/"
"$ICEF" bench --quick --out "$WORK/c" --threads 2 > "$WORK/c.txt" || fail "unsharded bench exited $?"
grep -q "bench: 7 runs in shard 0/1 (7 already done)" "$WORK/c.txt" || fail "unsharded plan: $(head -1 "$WORK/c.txt")"
diff <(grep -A4 "^## Verdict" "$WORK/c/report.md") <(grep -A4 "^## Verdict" "$R") || fail "verdicts differ"

# Training replicates: every run trained twice with its own seed, averaged per identity in the
# tables, their spread in a table of its own.
"$ICEF" bench --quick --methods icef --replicates 2 --out "$WORK/rep" --threads 2 > "$WORK/rep.txt" || fail "replicates exited $?"
ls "$WORK/rep/runs" | grep -qx "id1_k3_icef_r1" || fail "no second replicate: $(ls "$WORK/rep/runs")"
grep -q '"replicate": 1' "$WORK/rep/runs/id1_k3_icef_r1/metrics.json" || fail "replicate not recorded"
# Another training seed trains another model: the replicates differ.
if grep -q "| 3 | \`icef\` | observed | 1 | 2 | 0.00 |" "$WORK/rep/report.md"; then fail "replicates trained the same model"; fi
grep -q "^## Training-seed spread" "$WORK/rep/report.md" || fail "no training-seed spread in the report"
grep -q "| 3 | \`icef\` | far | 1 | 2 |" "$WORK/rep/report.md" || fail "spread row: $(grep -A6 'Training-seed' "$WORK/rep/report.md")"
if "$ICEF" bench --out "$WORK/x" --replicates 0 2> "$WORK/err.txt"; then fail "--replicates 0 accepted"; fi
grep -q "replicates" "$WORK/err.txt" || fail "unclear replicates error"

# Bad options exit 1 with a message.
if "$ICEF" bench --out "$WORK/x" --shard 2/2 2> "$WORK/err.txt"; then fail "bad shard accepted"; fi
grep -q "shard" "$WORK/err.txt" || fail "unclear shard error"
if "$ICEF" bench --out "$WORK/x" --methods icef,fdnerf 2> "$WORK/err.txt"; then fail "unknown method accepted"; fi
grep -q "fdnerf" "$WORK/err.txt" || fail "unclear method error"
# Validation seeds (101 and up) only with --validation, and --validation only with them.
if "$ICEF" bench --out "$WORK/x" --first-seed 101 2> "$WORK/err.txt"; then fail "validation seed in a test bench"; fi
grep -q "validation identities" "$WORK/err.txt" || fail "unclear seed error: $(cat "$WORK/err.txt")"
if "$ICEF" bench --out "$WORK/x" --validation --first-seed 3 2> "$WORK/err.txt"; then fail "test seed in a validation bench"; fi
grep -q "validation seeds" "$WORK/err.txt" || fail "unclear validation error: $(cat "$WORK/err.txt")"
echo "bench_quick_test: OK ($((SECONDS - start)) s)"
