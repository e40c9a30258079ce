#!/usr/bin/env bash
# One variant of the run config on the diverse validation identities, over several training seeds:
# for each identity seed and training seed, `icef train` then `icef eval` on the dataset's full
# test set (every held-out view), so that a prior's effect can be told from the training seed's.
#
#   scripts/validation_runs.sh --variant NAME [--set SECTION.KEY=VALUE ...] [--out DIR]
#       [--seeds "101 102 103 104 105 106"] [--train-seeds "0 1"] [--method icef] [--res 128]
#       [--k 5] [--steps 1000] [--icef build/icef] [--threads 0]
#
# Writes DIR/data/seed<S>_<res>/ (`icef synth --diverse`, made once; seed<S>_<res>_k<K>/ when K is not 5) and
# DIR/runs/<NAME>_<S>_t<T>/ (model, eval/metrics.json); runs that already have eval/metrics.json
# are kept. scripts/validation_table.py DIR tabulates them. Seeds must be validation identities
# (101 and up): the bench's test identities are never tuned on.
set -euo pipefail

icef=build/icef
out=validation_runs
variant=""
seeds="101 102 103 104 105 106"
train_seeds="0 1"
method=icef
res=128
k=5
steps=1000
threads=0
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --variant) variant=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    --out) out=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --train-seeds) train_seeds=$2; shift 2 ;;
    --method) method=$2; shift 2 ;;
    --res) res=$2; shift 2 ;;
    --k) k=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --icef) icef=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    -h|--help) sed -n 2,14p "$0"; exit 0 ;;
    *) echo "validation_runs.sh: unknown option $1" >&2; exit 1 ;;
  esac
done
if [ -z "$variant" ]; then
  echo "validation_runs.sh: --variant NAME is required" >&2
  exit 1
fi
for seed in $seeds; do
  if [ "$seed" -lt 101 ]; then
    echo "validation_runs.sh: seed $seed is a test identity (below 101); tune on validation seeds 101 and up" >&2
    exit 1
  fi
done

mkdir -p "$out/data" "$out/runs"
for seed in $seeds; do
  data="$out/data/seed${seed}_${res}"
  [ "$k" = 5 ] || data="${data}_k${k}"
  [ -f "$data/transforms_test.json" ] ||
    "$icef" synth --diverse --out "$data" --identity-seed "$seed" --k "$k" --res "$res" --threads "$threads" >/dev/null
  for ts in $train_seeds; do
    run="$out/runs/${variant}_${seed}_t${ts}"
    [ -f "$run/eval/metrics.json" ] && continue
    "$icef" train "$data" --out "$run" --method "$method" --steps "$steps" --seed "$ts" --threads "$threads" \
      --quiet --overwrite "${sets[@]}" >/dev/null
    "$icef" eval "$run" "$data" -o "$run/eval" --threads "$threads" >/dev/null
    echo "validation_runs: $variant seed $seed training seed $ts done" >&2
  done
done
