#!/usr/bin/env bash
# The tool's entry point: bare `icef` lists the subcommands (exit 1), --help and --version exit 0,
# an unknown subcommand or option is one clear error with exit 1.
set -euo pipefail
ICEF="$1"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

set +e
"$ICEF" > "$TMP/out" 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] || { echo "bare icef: expected exit 1, got $code" >&2; exit 1; }
for sub in demo synth train render eval bench track; do
  grep -q "^  $sub " "$TMP/err" || { echo "bare icef does not list '$sub'" >&2; cat "$TMP/err" >&2; exit 1; }
done

"$ICEF" --help > "$TMP/out"
grep -q "Subcommands:" "$TMP/out"
"$ICEF" --version | grep -q "^icef "

set +e
"$ICEF" frobnicate > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "unknown subcommand 'frobnicate'" "$TMP/err" && grep -q " track" "$TMP/err" \
  || { echo "unknown subcommand: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
[ "$(wc -l < "$TMP/err")" -eq 1 ]
set +e
"$ICEF" train "$TMP/data" --out "$TMP/model" --no-such-option > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "no-such-option" "$TMP/err" || { echo "unknown option: exit $code" >&2; exit 1; }

# A misspelt option is named even where a required argument is missing too (CLI11 alone would
# report only the missing --out), in nested subcommands as well, and at the top level.
set +e
"$ICEF" train "$TMP/data" --stpes 10 > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "icef train: unknown option '--stpes'" "$TMP/err" && [ "$(wc -l < "$TMP/err")" -eq 1 ] \
  || { echo "misspelt option before a missing one: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
set +e
"$ICEF" bench merge "$TMP/a" --out="$TMP/b" --frob > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "icef bench merge: unknown option '--frob'" "$TMP/err" \
  || { echo "nested unknown option: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
set +e
"$ICEF" --frob > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "icef: unknown option '--frob'" "$TMP/err" \
  || { echo "top-level unknown option: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
# Known options, `--opt=value`, a short flag and a negative number pass through to the command.
set +e
"$ICEF" train "$TMP/data" --out="$TMP/model" --steps 5 -h > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 0 ] || { echo "known options refused: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
set +e
"$ICEF" train "$TMP/data" --out "$TMP/model" --steps -5 > /dev/null 2> "$TMP/err"; code=$?
set -e
! grep -q "unknown option" "$TMP/err" || { echo "a negative value taken for an option" >&2; cat "$TMP/err" >&2; exit 1; }

# A number out of its range is named with the rule, in one line (not a range ending in 300 digits).
set +e
"$ICEF" train "$TMP/data" --out "$TMP/model" --steps 0 > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "^--steps: must be a number > 0, got '0'$" "$TMP/err" \
  || { echo "--steps 0: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }
set +e
"$ICEF" render "$TMP/model" --orbit -2 > /dev/null 2> "$TMP/err"; code=$?
set -e
[ "$code" -eq 1 ] && grep -q "^--orbit: must be a number >= 0, got '-2'$" "$TMP/err" \
  || { echo "--orbit -2: exit $code" >&2; cat "$TMP/err" >&2; exit 1; }

# `icef train --help` states the default step count, the one the resolved config holds.
steps=$("$ICEF" config | python3 -c 'import json, sys; print(json.load(sys.stdin)["train"]["steps"])')
"$ICEF" train --help | grep -q "default $steps;" || { echo "icef train --help does not give the default of $steps steps" >&2; exit 1; }
echo "cli_test: ok"
