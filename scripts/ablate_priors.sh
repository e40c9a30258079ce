#!/usr/bin/env bash
# Leave-one-out ablation of ICEF's few-shot priors and rendering choices: trains the default
# config and one variant per prior switched off on a synthetic subject, and writes a markdown
# table of the held-out PSNR at the training expressions (tier `observed`, summary.json's
# psnr_observed) and the wall time of each run.
#
#   scripts/ablate_priors.sh [--icef build/icef] [--out DIR] [--seeds "101 102 103"] [--k 5] [--res 128]
#                            [--steps 1000] [--threads 0] [--only "default no-symmetry ..."] [--diverse]
#
# Tuning uses validation identities only: the seeds must be 101 and up (the bench's test
# identities are below 101 and are never tuned on). --diverse renders the subjects in the
# validation bench's diverse scenes (`icef synth --diverse`, the resolution pinned by --res).
# Writes DIR/priors.md (and keeps each run's
# model directory under DIR/runs/). docs/results/priors_validation.md was made by this script.
set -euo pipefail

icef=build/icef
out=ablation
seeds="101 102 103"
only=""
k=5
res=128
steps=1000
threads=0
diverse=()
while [ $# -gt 0 ]; do
  case "$1" in
    --icef) icef=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --k) k=$2; shift 2 ;;
    --res) res=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --diverse) diverse=(--diverse); shift ;;
    -h|--help) sed -n 2,14p "$0"; exit 0 ;;
    *) echo "ablate_priors.sh: unknown option $1" >&2; exit 1 ;;
  esac
done

# name | what changes | --set overrides (empty: the defaults)
variants=(
  "default|all defaults (docs/config.md)|"
  "no-symmetry|left-right symmetry prior off|train.lambda_symmetry=0"
  "symmetry-4k|symmetry prior on 4096 mirrored samples per step instead of 16384|train.symmetry_max_samples=4096"
  "no-occlusion|occlusion sparsity prior off|train.lambda_occlusion=0"
  "distortion-1e-3|distortion loss weight 1e-3 instead of the default|train.lambda_distortion=0.001"
  "no-distortion|distortion loss off|train.lambda_distortion=0"
  "lambda-id-0.1|L_id weight 0.1 instead of the default|train.lambda_id=0.1"
  "jitter|training rays through random points of their pixels|train.pixel_jitter=true"
  "supersample-2|renders average 2 x 2 rays per pixel|model.render.supersample=2"
  "sh-degree-4|view-dependent colour, SH degree 4|model.static_field.sh_degree=4"
  "no-hull|no visual-hull prior|model.visual_hull.enabled=false"
  "no-random-bg|white background only|train.random_background=false"
)

join() { local IFS=/; echo "$*"; }

for seed in $seeds; do
  if [ "$seed" -lt 101 ]; then
    echo "ablate_priors.sh: seed $seed is a test identity (below 101); tune on validation seeds 101 and up" >&2
    exit 1
  fi
done

mkdir -p "$out/data" "$out/runs"
rows=()
for seed in $seeds; do
  data="$out/data/seed${seed}_k${k}_${res}"
  [ -f "$data/transforms_train.json" ] ||
    "$icef" synth --out "$data" --identity-seed "$seed" --k "$k" --res "$res" --threads "$threads" "${diverse[@]}" >/dev/null
done
for v in "${variants[@]}"; do
  IFS='|' read -r name what sets <<<"$v"
  if [ -n "$only" ] && ! grep -qw -- "$name" <<<"$only"; then continue; fi
  psnrs=()
  secs=()
  for seed in $seeds; do
    run="$out/runs/${name}_seed${seed}"
    args=()
    for s in $sets; do args+=(--set "$s"); done
    "$icef" train "$out/data/seed${seed}_k${k}_${res}" --out "$run" --steps "$steps" --seed 0 \
      --threads "$threads" --quiet --overwrite "${args[@]}" >/dev/null
    psnrs+=("$(python3 -c "import json;print('%.2f'%json.load(open('$run/summary.json'))['psnr_observed'])")")
    secs+=("$(python3 -c "import json;print('%.0f'%json.load(open('$run/summary.json'))['wall_seconds'])")")
    echo "ablate_priors: $name seed $seed: ${psnrs[-1]} dB, ${secs[-1]} s" >&2
  done
  mean=$(python3 -c "import sys;v=[float(x) for x in sys.argv[1:]];print('%.2f'%(sum(v)/len(v)))" "${psnrs[@]}")
  rows+=("| $name | $what | $(join "${psnrs[@]}") | $mean | $(join "${secs[@]}") |")
done

{
  echo "# Few-shot priors: leave-one-out ablation"
  echo
  echo "Made by \`scripts/ablate_priors.sh --seeds \"$seeds\" --k $k --res $res --steps $steps ${diverse[*]}\` on $(nproc) cores"
  echo "($(date -u +%Y-%m-%d)). Each row trains \`icef train --steps $steps\` (the default method) on the synthetic"
  echo "subject of each identity seed (K = $k, ${res}x${res}) with one change from the defaults, and reports"
  echo "summary.json's \`psnr_observed\`: mean PSNR over the held-out test views at the training expressions."
  echo
  echo "| variant | change | held-out PSNR per seed (dB) | mean (dB) | wall seconds per seed |"
  echo "|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
} >"$out/priors.md.tmp"
mv "$out/priors.md.tmp" "$out/priors.md"
echo "wrote $out/priors.md"
