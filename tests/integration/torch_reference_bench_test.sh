#!/usr/bin/env bash
# scripts/torch_reference_bench.py (`make bench`'s PyTorch comparison): the reference step's
# modules have the C++ reference model's sizes (src/icef/nn/reference_model.h: MLP weights
# 55*64 + 64*64 + 64*64 + 64*3, 32*64 + 64*16, 32*64 + 64*64 + 64*3 = 21312; 131072 samples per step),
# a step trains (finite loss, positive rate), and the ratios against icef_bench's JSON are the
# rates' quotients (the default train step's: bf16:1/composited:1). Skipped (77) where python3-torch is not installed (`scripts/install-deps.sh --bench`).
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
if ! /usr/bin/python3 -c "import torch" 2>/dev/null; then
  echo "SKIP: python3-torch is not installed (scripts/install-deps.sh --bench)"
  exit 77
fi
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cat > "$TMP/cpp.json" <<'JSON'
{"benchmarks": [{"name": "BM_ReferenceTrainStep", "samples_per_second": 1000000.0},
                {"name": "BM_TrainStep/bf16:1/composited:0/min_time:3.000/real_time", "samples/s": 400000.0},
                {"name": "BM_TrainStep/bf16:1/composited:1/min_time:3.000/real_time", "samples/s": 500000.0}]}
JSON
/usr/bin/python3 "$HERE/../../scripts/torch_reference_bench.py" --steps 1 --warmup 0 --threads 2 \
  --cpp-results "$TMP/cpp.json" --json "$TMP/out.json"
/usr/bin/python3 - "$TMP/out.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
def check(ok, what):
    if not ok:
        sys.exit(f"torch_reference_bench_test: {what}: {r}")
check(r["mlp_weights"] == 21312, "MLP weights differ from the C++ reference model's")
check(r["samples_per_step"] == 131072, "samples per step differ from BM_ReferenceTrainStep's 4096 x 32")
check(math.isfinite(r["loss"]) and r["samples_per_second"] > 0, "no finite loss or rate")
check(abs(r["ratio_BM_ReferenceTrainStep"] * r["samples_per_second"] - 1e6) < 1e-3, "reference ratio")
check(abs(r["ratio_BM_TrainStep"] * r["samples_per_second"] - 5e5) < 1e-3, "train-step ratio")
print("torch_reference_bench_test: ok")
PY
