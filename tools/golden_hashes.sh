#!/usr/bin/env bash
# Writes tests/data/golden_hashes.tsv: the state hash of every example world
# (worlds/*.yaml, worlds/experiments/*.yaml, worlds/kilobot/*.yaml, bench/worlds/*.yaml) and of the coverage worlds
# (tests/data/worlds/golden_*.yaml: every object type, copied and scaled) after a fixed number of steps, for two
# seeds and 1 and 2 threads, as `swarmsim run WORLD --hash` prints it.
# tests/swarm/run/golden_hashes_test.cc fails when any of them drifts.
#
# Run it only when a change of results is intended, and say why in the
# commit:   tools/golden_hashes.sh [BUILD_DIR]      (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
program="${1:-build}/swarmsim"
[ -x "$program" ] || { echo "golden_hashes: no program at $program (build first)" >&2; exit 2; }
steps=200
table=tests/data/golden_hashes.tsv
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
printf '# world\tseed\tsteps\tthreads\tstate_hash   (written by tools/golden_hashes.sh)\n' >"$tmp"
# A world reading a map beside the repository (../../shared/maps/, not in it)
# that is not there keeps its rows of the old table.
missing_map() {
  local map
  for map in $(grep -o '\.\./\.\./shared/maps/[A-Za-z0-9_.-]*' "$1"); do
    [ -e "$(dirname "$1")/$map" ] || { echo "$map"; return 0; }
  done
  return 1
}
for world in worlds/*.yaml worlds/experiments/*.yaml worlds/kilobot/*.yaml bench/worlds/*.yaml tests/data/worlds/golden_*.yaml; do
  if map=$(missing_map "$world"); then
    echo "golden_hashes: $world: $map is not here; its rows are kept" >&2
    grep -P "^\Q$world\E\t" "$table" >>"$tmp" || true
    continue
  fi
  for seed in 1 7; do
    for threads in 1 2; do
      line=$("$program" run "$world" --seed "$seed" --steps "$steps" --threads "$threads" \
               --hash --quiet 2>&1 | grep '^state-hash: ') ||
        { echo "golden_hashes: $world --seed $seed failed" >&2; exit 1; }
      printf '%s\t%s\t%s\t%s\t%s\n' "$world" "$seed" "$steps" "$threads" "${line#state-hash: }" >>"$tmp"
    done
  done
done
mv "$tmp" "$table"
trap - EXIT
echo "wrote $table ($(grep -vc '^#' "$table") rows)"
