#!/usr/bin/env bash
# Crash safety of training. On a tiny synthetic dataset and config (tests/reliability/tiny_config.json,
# 120 steps, a checkpoint every 4 steps):
#  1. an uninterrupted reference run;
#  2. runs killed with SIGKILL at random moments of the reference duration: whatever is on disk must
#     be a checkpoint that loads (`icef render` of it succeeds) or no checkpoint at all, and
#     `--resume` must finish the run and give exactly the reference run's image;
#  3. a run stopped with SIGINT: it must exit cleanly with a final checkpoint, and `--resume` must
#     give the reference run's image too.
# Usage: kill_test.sh PATH/TO/icef [ROUNDS]
set -euo pipefail
ICEF=$(realpath "$1")
ROUNDS=${2:-4}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
CONFIG=$ROOT/tests/reliability/tiny_config.json
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

if ! grep -qE '^ +train( |$)' <<<"$("$ICEF" --help 2>/dev/null || true)"; then  # no pipe: see reliability_test.sh
  echo "SKIP: this build has no \`icef train\`"
  exit 77
fi

"$ICEF" synth --out "$WORK/data" --k 3 --res 16 --test-views 1 --novel-per-tier 1 --threads 2 > /dev/null 2>&1 ||
  fail "icef synth failed"
# 120 steps (30 checkpoints): long enough that kills and the SIGINT land mid-run on an idle machine.
train() { "$ICEF" train "$WORK/data" --config "$CONFIG" --steps 120 --threads 2 --quiet "$@"; }
# Background runs start icef directly (not through the function) so that $! is icef's own pid.
TRAIN=("$ICEF" train "$WORK/data" --config "$CONFIG" --steps 120 --threads 2 --quiet)
render() {  # render MODEL OUT: the model's image at the default camera
  "$ICEF" render "$1" --out "$2" --res 16 --threads 2 > "$2.log" 2>&1
}
first_png() { find "$1" -name '*.png' | sort | head -n 1; }

# 1. Reference.
start=$(date +%s.%N)
train --out "$WORK/ref" > "$WORK/ref.log" 2>&1 || { cat "$WORK/ref.log"; fail "reference training failed"; }
ref_seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.3f", b - a }')
render "$WORK/ref" "$WORK/ref_render" || { cat "$WORK/ref_render.log"; fail "render of the reference model failed"; }
ref_png=$(first_png "$WORK/ref_render")
[ -n "$ref_png" ] || fail "render wrote no PNG"
echo "reference run: ${ref_seconds}s"

# 2. SIGKILL at random moments within the reference run's duration.
RANDOM=7
for round in $(seq 1 "$ROUNDS"); do
  model=$WORK/kill_$round
  delay=$(awk -v t="$ref_seconds" -v r=$((RANDOM % 1000)) 'BEGIN { printf "%.3f", t * r / 1000 }')
  "${TRAIN[@]}" --out "$model" > "$WORK/kill_$round.log" 2>&1 &
  pid=$!
  sleep "$delay"
  hit="killed while running"
  kill -9 "$pid" 2>/dev/null || hit="had already finished"
  wait "$pid" 2>/dev/null || true
  kill -0 "$pid" 2>/dev/null && fail "round $round: the training process survived kill -9"
  state="no checkpoint yet"
  if [ -f "$model/checkpoint.icef" ]; then
    render "$model" "$WORK/kill_${round}_render" ||
      { cat "$WORK/kill_${round}_render.log"; fail "round $round: checkpoint left by kill -9 after ${delay}s does not load"; }
    state="checkpoint loads"
  fi
  # A fresh start when nothing was checkpointed yet, else a resume.
  if [ -f "$model/checkpoint.icef" ]; then
    train --out "$model" --resume > "$WORK/resume_$round.log" 2>&1 ||
      { cat "$WORK/resume_$round.log"; fail "round $round: --resume after kill -9 failed"; }
  else
    train --out "$model" --overwrite > "$WORK/resume_$round.log" 2>&1 ||
      { cat "$WORK/resume_$round.log"; fail "round $round: training again after kill -9 failed"; }
  fi
  render "$model" "$WORK/resumed_${round}_render" || fail "round $round: render after resume failed"
  cmp -s "$ref_png" "$(first_png "$WORK/resumed_${round}_render")" ||
    fail "round $round: resumed model renders differently from the uninterrupted run"
  leftovers=$(find "$model" -name '*.tmp*' | wc -l)
  echo "round $round: kill -9 after ${delay}s ($hit): $state; resumed run matches the reference ($leftovers stale temporaries)"
done

# 3. SIGINT: clean stop with a final checkpoint, then resume.
model=$WORK/sigint
"${TRAIN[@]}" --out "$model" > "$WORK/sigint.log" 2>&1 &
pid=$!
for _ in $(seq 1 3000); do [ -f "$model/checkpoint.icef" ] && break; sleep 0.01; done
kill -INT "$pid" 2>/dev/null || fail "SIGINT: training ended before the signal (make the run longer)"
rc=0
wait "$pid" || rc=$?
[ "$rc" -eq 0 ] || { cat "$WORK/sigint.log"; fail "SIGINT: exit code $rc, expected 0"; }
[ -f "$model/checkpoint.icef" ] || fail "SIGINT: no final checkpoint"
grep -Eq '"interrupted": *true' "$model/summary.json" || fail "SIGINT: summary.json does not say the run was interrupted"
render "$model" "$WORK/sigint_render" || fail "SIGINT: the final checkpoint does not load"
train --out "$model" --resume > "$WORK/sigint_resume.log" 2>&1 || { cat "$WORK/sigint_resume.log"; fail "SIGINT: --resume failed"; }
render "$model" "$WORK/sigint_resumed_render" || fail "SIGINT: render after resume failed"
cmp -s "$ref_png" "$(first_png "$WORK/sigint_resumed_render")" ||
  fail "SIGINT: resumed model renders differently from the uninterrupted run"
echo "SIGINT: clean stop with a final checkpoint; resumed run matches the reference"
echo "kill_test: OK"
