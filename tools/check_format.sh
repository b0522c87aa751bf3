#!/usr/bin/env bash
# Fails when a tracked C++ file is not clang-formatted (.clang-format at the
# repo root). Run by the test suite; skipped when clang-format is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-format >/dev/null 2>&1; then
  echo "clang-format not installed: format check skipped"
  exit 0
fi
bad=()
while IFS= read -r f; do
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done < <(git ls-files '*.h' '*.cc' 2>/dev/null || find framework modules swarm tests bench -name '*.h' -o -name '*.cc')
if [ ${#bad[@]} -gt 0 ]; then
  printf 'not clang-formatted (run: clang-format -i FILE):\n'
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "all C++ files clang-formatted"
