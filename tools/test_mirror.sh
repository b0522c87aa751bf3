#!/usr/bin/env bash
# Which source units have a mirrored test file (issue 27: tests mirror sources).
#
#   tools/test_mirror.sh            # the units without one, then the share
#   tools/test_mirror.sh --all      # every unit, with its test or "-"
#
# A unit is a .cc under framework/, modules/ or swarm/ (not the plugins'
# examples, the program's main or registration lists: see `skip` below); its
# mirrored test is tests/<same folder>/<unit>_test.cc, or for the Python
# binding tests/python/test_<unit>.py.
set -euo pipefail
cd "$(dirname "$0")/.."
skip='^(modules/plugins/|swarm/cli/main\.cc$|modules/builtin\.cc$|modules/dynamics/box2d/b2_timer_override\.cc$|framework/types/core_types\.cc$)'
all=0 have=0
while read -r src; do
  [[ "$src" =~ $skip ]] && continue
  dir=$(dirname "$src") unit=$(basename "$src" .cc)
  test="tests/$dir/${unit}_test.cc"
  [ "$dir" = swarm/python ] && test="tests/python/test_${unit}.py"
  all=$((all + 1))
  if [ -f "$test" ]; then
    have=$((have + 1))
    [ "${1:-}" = --all ] && echo "$src  $test"
  else
    echo "$src  -"
  fi
done < <(git ls-files 'framework/*.cc' 'modules/*.cc' 'swarm/*.cc' | sort)
echo "mirrored: $have of $all units ($((100 * have / all))%)"
