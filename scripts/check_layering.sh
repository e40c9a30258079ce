#!/usr/bin/env bash
# scripts/check_layering.sh: keeps the house in the shape docs/design.md and STYLE.md
# describe. Fails (exit 1), listing every offender, when
#  1. a file of src/icef/cli/ includes a project header outside icef/app/, icef/core/ and icef/cli/
#     (each subcommand is a thin adapter: it parses options and calls one app function);
#  2. src/icef/cli/module.cmake links the `icef` executable against anything but icef_app;
#  3. a production function (not in a *_test.cc) in src/icef/{train,eval,study,cli,app}/ is longer
#     than 80 lines (counted as clang-tidy's readability-function-size counts them).
set -uo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root" || exit 2
failed=0

# 1. What cli/ includes.
includes=$(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"icef/' src/icef/cli/*.cc src/icef/cli/*.h |
  grep -vE '"icef/(app|core|cli)/' || true)
if [ -n "$includes" ]; then
  echo "check_layering: src/icef/cli/ may include only icef/app/, icef/core/ and icef/cli/ headers" \
    "(a type from a lower module comes through an app header):"
  echo "$includes" | sed 's/^/  /'
  failed=1
fi

# 2. What the icef executable links.
links=$(grep -E 'target_link_libraries\(icef[[:space:]]' src/icef/cli/module.cmake || true)
if [ "$links" != "target_link_libraries(icef PRIVATE icef_app)" ]; then
  echo "check_layering: src/icef/cli/module.cmake must link the icef executable against icef_app only;" \
    "it has:"
  echo "${links:-  (no target_link_libraries(icef ...) line)}" | sed 's/^/  /'
  failed=1
fi

# 3. Function length (scripts/function_lengths.py: clang-tidy's readability-function-size count,
# from the text, in well under a second).
threshold=80
mapfile -t files < <(ls src/icef/{train,eval,study,cli,app}/*.cc | grep -v '_test\.cc$')
if ! long=$(python3 scripts/function_lengths.py --max "$threshold" "${files[@]}"); then
  echo "check_layering: production functions longer than $threshold lines in src/icef/{train,eval,study,cli,app}/" \
    "(split them into named pieces):"
  echo "$long" | sed 's/^/  /'
  failed=1
fi
echo "check_layering: measured ${#files[@]} files"

if [ "$failed" != 0 ]; then exit 1; fi
echo "check_layering: OK"
