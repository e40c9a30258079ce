#!/usr/bin/env bash
# scripts/function_lengths.py finds the functions over the limit, and only those: braces in strings,
# comments and initialisers, namespaces, classes and lambdas do not fool it.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)  # ($1, $2: the tool and the clip maker, unused)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
body() { for i in $(seq "$1"); do echo "  x += $i;  // }"; done; }
{
  echo 'namespace a {'
  echo 'namespace {'
  echo 'struct S { int Get() const { return 1; } };'
  echo 'const int kTable[] = {1, 2, 3};'
  echo '}  // namespace'
  echo 'int Short(int x) {'
  body 10
  echo '  return x;'
  echo '}'
  echo 'int Long(int x,'
  echo '         int y) {'
  echo '  const char* s = "{ not a brace";'
  echo "  const char c = '{';"
  echo '  auto f = [&](int z) {'
  body 40
  echo '    return z;'
  echo '  };'
  body 40
  echo '  return x + y + f(1);'
  echo '}'
  echo 'int Edge(int x) {'
  body 78
  echo '}'
  echo '}  // namespace a'
  echo 'Status Klass::Method() const {'
  echo '  /* { */'
  body 90
  echo '  return Status::Ok();'
  echo '}'
} >"$tmp/fixture.cc"
set +e
out=$(python3 "$root/scripts/function_lengths.py" --max 80 "$tmp/fixture.cc")
rc=$?
set -e
expected="$tmp/fixture.cc:20: Long: 88 lines
$tmp/fixture.cc:189: Klass::Method: 94 lines"
if [ "$rc" != 1 ] || [ "$out" != "$expected" ]; then
  echo "function_lengths_test: expected (exit 1):"; echo "$expected"
  echo "got (exit $rc):"; echo "$out"
  exit 1
fi
# Edge is 80 lines (its braces on lines 108 and 187): at the limit, not over it.
at_79=$(python3 "$root/scripts/function_lengths.py" --max 79 "$tmp/fixture.cc" || true)
grep -q ': Edge: 80 lines' <<<"$at_79" || { echo "function_lengths_test: Edge (80 lines) not reported at --max 79"; exit 1; }
echo "function_lengths_test: OK"
