#!/usr/bin/env bash
# Runs every hostile input of tests/reliability/cases through the CLI and checks, per case: the
# exit code (1 for a rejection: never a crash, a signal or an internal error), that stderr holds
# exactly one error line naming the file/field the case lists, and that nothing was left on disk
# (no output, no temporary, no changed input). It generates the table of docs/reliability.md from
# what it saw and fails when the committed document differs (a row's behaviour changed).
#
# Usage: reliability_test.sh PATH/TO/icef [--update]   (--update rewrites docs/reliability.md)
set -uo pipefail
ICEF=$(realpath "$1")
UPDATE=${2:-}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
CORPUS=$ROOT/tests/reliability
DOC=$ROOT/docs/reliability.md
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# Whether this build's CLI has a subcommand (the integrator adds train/render later).
# The help text is read once: piping `icef --help` into `grep -q` lets grep exit at the first match,
# and under pipefail the SIGPIPE that icef may then get made the check fail at random.
ICEF_HELP=$("$ICEF" --help 2>/dev/null || true)
has_command() { grep -qE "^ +$1( |$)" <<<"$ICEF_HELP"; }

# Shared fixtures, made on first use: a synthetic dataset and a tiny trained model.
SYNTH=$WORK/fixtures/synth
MODEL=$WORK/fixtures/model
fixture_synth() {
  [ -d "$SYNTH" ] && return 0
  "$ICEF" synth --out "$SYNTH" --k 3 --res 16 --test-views 1 --novel-per-tier 1 --threads 2 >/dev/null 2>&1
}
fixture_model() {
  [ -f "$MODEL/checkpoint.icef" ] && return 0
  fixture_synth || return 1
  "$ICEF" train "$SYNTH" --out "$MODEL" --config "$CORPUS/tiny_config.json" --threads 2 --quiet >/dev/null 2>&1
}

# Damages MODEL_DIR/checkpoint.icef in one of the ways a case names.
mutate_checkpoint() {  # mutate_checkpoint MODEL_DIR KIND [ARGS...]
  local f=$1/checkpoint.icef size kind=$2
  shift 2
  size=$(stat -c %s "$f")
  case $kind in
    truncate-half) truncate -s $((size / 2)) "$f" ;;
    flip-bit)
      local byte
      byte=$(od -An -tu1 -j $((size / 2)) -N1 "$f" | tr -d ' ')
      printf "$(printf '\\%03o' $((byte ^ 16)))" | dd of="$f" bs=1 seek=$((size / 2)) conv=notrunc status=none ;;
    empty) : > "$f" ;;
    png) cp "$CORPUS/base/images/train_000.png" "$f" ;;
    delete) rm -f "$f" ;;
    set-json) python3 "$CORPUS/edit_checkpoint.py" "$f" "$@" ;;  # SECTION KEY VALUE, resealed
    *) echo "unknown mutation $kind" >&2; return 1 ;;
  esac
}

snapshot() {  # snapshot DIR: one line per file (hash + path) and per directory
  (cd "$1" && find . -mindepth 1 -type d -printf 'dir %p\n' | sort && find . -type f -print0 | sort -z | xargs -0 -r sha1sum)
}

# What changed between two snapshots: "nothing", or created/changed/removed paths.
disk_changes() {  # disk_changes BEFORE AFTER
  local created changed removed out=""
  created=$(comm -13 <(sed 's/^[^ ]* //' "$1" | sort -u) <(sed 's/^[^ ]* //' "$2" | sort -u) | sed 's|^\./||' | tr '\n' ' ')
  removed=$(comm -23 <(sed 's/^[^ ]* //' "$1" | sort -u) <(sed 's/^[^ ]* //' "$2" | sort -u) | sed 's|^\./||' | tr '\n' ' ')
  changed=$(comm -12 <(sed 's/^[^ ]* //' "$1" | sort -u) <(sed 's/^[^ ]* //' "$2" | sort -u) | while read -r p; do
    [ "$(grep -F "  $p" "$1")" = "$(grep -F "  $p" "$2")" ] || printf '%s ' "${p#./}"; done)
  [ -n "$created" ] && out+="created: ${created% } "
  [ -n "$changed" ] && out+="changed: ${changed% } "
  [ -n "$removed" ] && out+="removed: ${removed% } "
  echo "${out:-nothing}" | sed 's/ *$//'
}

md_escape() { sed 's/|/\\|/g; s/`/'"'"'/g'; }

ROWS=$WORK/rows.md
: > "$ROWS"
for case_dir in "$CORPUS"/cases/*/; do
  name=$(basename "$case_dir")
  spec=$case_dir/case.txt
  field() { sed -n "s/^$1: //p" "$spec"; }
  what=$(field what); run=$(field run); want_exit=$(field exit); expect=$(field expect)
  remove=$(field remove); needs=$(field needs); mutate=$(field mutate)
  want_left=$(field leaves); want_left=${want_left:-nothing}  # a known gap is recorded, not hidden

  if [ -n "$needs" ] && ! has_command "$needs"; then
    printf '| %s | `icef %s` | not run: this build has no `icef %s` | | |\n' "$what" "$run" "$needs" >> "$ROWS"
    continue
  fi
  cw=$WORK/cases/$name
  mkdir -p "$cw"
  cp -r "$CORPUS/base" "$cw/data"
  [ -d "$case_dir/files" ] && cp -r "$case_dir/files/." "$cw/data/"
  for r in $remove; do rm -f "$cw/data/$r"; done
  if [[ $run == *"{synth}"* ]]; then
    fixture_synth || { fail "$name: could not make the synthetic dataset fixture"; continue; }
    cp -r "$SYNTH" "$cw/synth"
  fi
  if [[ $run == *"{model}"* ]]; then
    fixture_model || { fail "$name: could not train the tiny model fixture"; continue; }
    cp -r "$MODEL" "$cw/model"
    # shellcheck disable=SC2086  # a mutation is a kind and its arguments
    [ -n "$mutate" ] && { mutate_checkpoint "$cw/model" $mutate || { fail "$name: bad mutation"; continue; }; }
  fi
  args=${run//\{data\}/$cw/data}
  args=${args//\{out\}/$cw/out}
  args=${args//\{model\}/$cw/model}
  args=${args//\{synth\}/$cw/synth}

  snapshot "$cw" > "$WORK/before"
  # shellcheck disable=SC2086  # args are split on purpose (no spaces in the paths used here)
  (cd "$cw" && timeout 300 "$ICEF" $args > "$WORK/stdout" 2> "$WORK/stderr")
  rc=$?
  snapshot "$cw" > "$WORK/after"
  left=$(disk_changes "$WORK/before" "$WORK/after")

  # Error lines: stderr without progress-bar redraws, paths shown relative to the case directory.
  tr '\r' '\n' < "$WORK/stderr" | grep -v '^\s*$' | grep -v '\[#*[ -]*\]' | sed "s|$cw/||g; s|$WORK/||g" > "$WORK/errors"
  # The table shortens lists of valid keys (they grow with every new option); checks use the full text.
  message=$(head -n 3 "$WORK/errors" | tr '\n' ' ' | sed 's/ *$//; s/(valid keys: [^)]*)/(valid keys: ...)/')
  nlines=$(wc -l < "$WORK/errors")

  if [ "$rc" -ne "$want_exit" ]; then fail "$name: exit code $rc, expected $want_exit"; fi
  if [ "$rc" -ge 2 ] || grep -qE 'AddressSanitizer|runtime error:|internal error|Segmentation|Aborted' "$WORK/stderr"; then
    fail "$name: crashed or internal error (exit $rc): $message"
  fi
  if [ "$want_exit" -eq 1 ] && [ "$nlines" -ne 1 ]; then fail "$name: expected one error line, got $nlines: $message"; fi
  if [ "$want_exit" -eq 0 ] && [ "$nlines" -ne 0 ]; then fail "$name: expected no error output, got: $message"; fi
  IFS='|' read -r -a needles <<< "$expect"
  for needle in "${needles[@]}"; do
    needle=$(echo "$needle" | sed 's/^ *//; s/ *$//')
    [ -z "$needle" ] && continue
    grep -qF -- "$needle" "$WORK/errors" || fail "$name: message does not name '$needle': $message"
  done
  [ "$left" = "$want_left" ] || fail "$name: left on disk: $left (expected: $want_left)"

  [ -z "$message" ] && message="(accepted; no error)"
  printf '| %s | `icef %s` | %s | %s | %s |\n' "$(echo "$what" | md_escape)" \
    "$(echo "$run" | md_escape)" "$(echo "$message" | md_escape)" "$rc" "$left" >> "$ROWS"
done

GENERATED=$WORK/reliability.md
{
  cat <<'EOF'
# Reliability: what ICEF does with hostile input

Generated by `tests/integration/reliability_test.sh` (part of `make test`) from the corpus in
`tests/reliability/` — do not edit by hand; after an intended change run
`bash tests/integration/reliability_test.sh build/icef --update`.

Every row is one malformed input run through the command-line tool. The test fails when a row's
behaviour changes: an exit code other than the expected one (1 for a rejection; never a crash or
an internal error), a message that does not name the file and field, more than one error line, or
anything left behind on disk. Placeholders: `{data}` a copy of `tests/reliability/base` with the
case's files applied, `{out}` an output path, `{synth}` a synthetic dataset, `{model}` a tiny
trained model (damaged as the row says). Paths in messages are relative to the case directory.

| input | command | what the program says (stderr) | exit | left on disk |
|---|---|---|---|---|
EOF
  cat "$ROWS"
  cat <<'EOF'

`icef info` (and every dataset load) checks each image's header and file structure (PNG: every
chunk complete, critical chunks' CRCs, IEND; JPEG: every segment complete up to the end-of-image
marker) but does not decode pixels, for speed (2021 PNGs of 128x128: 0.027 s for the checks,
0.48 s to decode; decoding grows with the pixel count, about 3.6 ms per 512x512 PNG). Damage that
leaves the structure intact, such as corrupt JPEG scan data, is found when `icef train` (or `eval`)
decodes the image (libpng and libjpeg-turbo; every decoder error and every corrupt-data warning is
an error naming the file).

Related guarantees tested elsewhere: checkpoints are written to a temporary file, flushed and
renamed (`io/atomic_file`), carry a format version, the config hash and an FNV-1a checksum, and a
truncated or bit-flipped file is refused (`io/checkpoint_test`, rows above); the trainer state's
step range and the config hash are checked on load (`train/model_io_test`; for inference loads,
`model/trained_model_test`, with damaged files, other format versions and missing sections);
`tests/integration/kill_test.sh` kills training with SIGKILL at random moments and checks that the
checkpoint always loads and `--resume` continues; `src/icef/train/nan_guard_test.cc` checks that a
non-finite loss stops training with the step and the term named and the previous checkpoint intact
(`train.on_nonfinite = "stop"`, the default), or with `"skip"` that the step is skipped, counted in
summary.json as `skipped_steps`, and that the 11th non-finite step in a row still stops training.
The fuzzers in `fuzz/` (`make fuzz`) cover the dataset loader, the checkpoint reader and the image
reader; their former findings are regression seeds in `fuzz/corpus/` (`io/image_test` reads them).
EOF
} > "$GENERATED"

if [ "$UPDATE" = "--update" ]; then
  cp "$GENERATED" "$DOC"
  echo "wrote $DOC"
elif ! diff -u "$DOC" "$GENERATED" > "$WORK/doc.diff"; then
  cat "$WORK/doc.diff" >&2
  fail "docs/reliability.md differs from what the CLI does now (rows above); if intended, rerun with --update"
fi

if [ "$failures" -ne 0 ]; then
  echo "reliability: $failures failure(s)" >&2
  exit 1
fi
echo "reliability: $(grep -c '^| ' "$ROWS") cases OK"
