#!/usr/bin/env bash
# scripts/torch_reference_bench.py (`make bench`'s PyTorch comparison): the kernels have the sizes of
# bench/nn_bench.cc's (MLP weights 55*64 + 64*64 + 64*64 + 64*3 = 11904, 32*64 + 64*16 = 3072,
# 32*64 + 64*64 + 64*3 = 6336; the reference hash grid's 11.5 M-float table; 131072 samples per
# call), every kernel runs (positive rates), and the ratios against icef_bench's JSON are the rates'
# quotients, matched by name without the run options. Skipped (77) where python3-torch is not
# installed (`scripts/install-deps.sh --bench`).
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
if ! /usr/bin/python3 -c "import torch" 2>/dev/null; then
  echo "SKIP: python3-torch is not installed (scripts/install-deps.sh --bench)"
  exit 77
fi
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cat > "$TMP/cpp.json" <<'JSON'
{"benchmarks": [{"name": "BM_GemmFp32", "flops_per_second": 1e11},
                {"name": "BM_HashGridForwardBackward/min_time:1.000/real_time", "samples_per_second": 1000000.0},
                {"name": "BM_MlpForwardBackward/2/min_time:0.500/real_time", "samples_per_second": 500000.0},
                {"name": "BM_TrainStep/bf16:1/composited:1/min_time:3.000/real_time", "samples/s": 400000.0}]}
JSON
/usr/bin/python3 "$HERE/../../scripts/torch_reference_bench.py" --steps 1 --warmup 0 --threads 2 \
  --cpp-results "$TMP/cpp.json" --json "$TMP/out.json"
/usr/bin/python3 - "$TMP/out.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
def check(ok, what):
    if not ok:
        sys.exit(f"torch_reference_bench_test: {what}: {r}")
check(r["mlp_weights"] == [11904, 3072, 6336], "MLP weights differ from bench/nn_bench.cc's")
check(11_300_000 < r["grid_params"] < 11_600_000, "the table differs from the reference hash grid's")
check(r["samples_per_step"] == 131072, "samples per call differ from nn_bench's 4096 x 32")
names = ["BM_HashGridForward", "BM_HashGridForwardBackward"] + \
    [f"BM_Mlp{p}/{k}" for p in ("Forward", "ForwardBackward") for k in range(3)]
check(sorted(r["kernels"]) == sorted(names), "kernels")
check(all(v > 0 for v in r["kernels"].values()), "a kernel has no positive rate")
check(sorted(r["ratios"]) == ["BM_HashGridForwardBackward", "BM_MlpForwardBackward/2"], "ratios")
check(abs(r["ratios"]["BM_HashGridForwardBackward"] * r["kernels"]["BM_HashGridForwardBackward"] - 1e6) < 1e-3,
      "grid ratio")
check(abs(r["ratios"]["BM_MlpForwardBackward/2"] * r["kernels"]["BM_MlpForwardBackward/2"] - 5e5) < 1e-3,
      "colour MLP ratio")
print("torch_reference_bench_test: ok")
PY
