#!/usr/bin/env bash
# What the render-time occupancy grid changes: re-evaluates every model a bench kept
# (`icef bench --keep-models`) with the training grid (`icef eval --training-occupancy`: training
# expressions only, cut to the training visual hull, as renders were placed before) and writes a
# table of each method's mean expr_gain and PSNR per tier, with the training grid ("before") and
# with the grid of the rendered expression ("after", the bench's own metrics.json).
#
#   scripts/occupancy_before_after.sh BENCH_DIR [--icef build/icef] [--out FILE]
#
# Writes FILE (default BENCH_DIR/occupancy_before_after.md); the per-run evaluations go to
# BENCH_DIR/runs/<run>/eval_training_occupancy/.
set -euo pipefail
bench=${1:?usage: occupancy_before_after.sh BENCH_DIR [--icef build/icef] [--out FILE]}
shift
icef=build/icef
out="$bench/occupancy_before_after.md"
while [ $# -gt 0 ]; do
  case "$1" in
    --icef) icef=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "occupancy_before_after.sh: unknown option $1" >&2; exit 1 ;;
  esac
done
runs=()
for dir in "$bench"/runs/*/; do
  name=$(basename "$dir")
  if [ ! -d "$dir/model" ]; then
    echo "occupancy_before_after.sh: $name has no kept model (run the bench with --keep-models)" >&2
    exit 1
  fi
  data="$bench/data/$(sed -E 's/^(id[0-9]+_k[0-9]+)_.*/\1/' <<<"$name")"
  if [ ! -f "$dir/eval_training_occupancy/metrics.json" ]; then
    "$icef" eval "$dir/model" "$data" --out "$dir/eval_training_occupancy" --training-occupancy >/dev/null
  fi
  runs+=("$name")
done
python3 - "$bench" "$out" "${runs[@]}" <<'PY'
import json, sys, collections
bench, out, runs = sys.argv[1], sys.argv[2], sys.argv[3:]
tiers = ["observed", "near", "moderate", "far"]
acc = collections.defaultdict(list)  # (method, k, tier, which, metric) -> values over identities
methods = []
for name in runs:
    after = json.load(open(f"{bench}/runs/{name}/metrics.json"))
    before = json.load(open(f"{bench}/runs/{name}/eval_training_occupancy/metrics.json"))
    method, k = after["run"]["method"], after["run"]["k"]
    if method not in methods:
        methods.append(method)
    for which, m in (("before", before), ("after", after)):
        for t in tiers:
            for metric in ("expr_gain", "psnr"):
                v = m["tiers"][t][metric]
                if v is not None:
                    acc[(method, k, t, which, metric)].append(v)
def mean(v):
    return sum(v) / len(v) if v else float("nan")
ks = sorted({k for (_, k, _, _, _) in acc})
lines = ["# Render-time occupancy: before and after", "",
         f"Made by `scripts/occupancy_before_after.sh {bench}` from the models the bench kept. "
         "\"before\": samples placed by the training grid (training expressions only, cut to the training "
         "visual hull: `icef eval --training-occupancy`); \"after\": by the grid of the rendered expression "
         "(the default; the bench's own numbers). Means over identities.", ""]
for k in ks:
    lines += [f"## K = {k}", "", "| method | tier | expr_gain before | expr_gain after | PSNR before | PSNR after |",
              "|---|---|---|---|---|---|"]
    for method in methods:
        for t in tiers[1:]:
            g0, g1 = mean(acc[(method, k, t, "before", "expr_gain")]), mean(acc[(method, k, t, "after", "expr_gain")])
            p0, p1 = mean(acc[(method, k, t, "before", "psnr")]), mean(acc[(method, k, t, "after", "psnr")])
            lines.append(f"| `{method}` | {t} | {g0:.3f} | {g1:.3f} | {p0:.2f} | {p1:.2f} |")
    lines.append("")
open(out, "w").write("\n".join(lines))
print("wrote", out)
PY
