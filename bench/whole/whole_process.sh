#!/bin/sh
# Whole-process robot-ticks per second, start-up included, as the issue's
# table and ARGoS comparisons measure them: one `swarmsim run` per row, the
# median of REPEAT runs (default 3).
#   bench/whole/whole_process.sh [BUILD_DIR] > table.txt
#   WORLDS="worlds/diffusion.yaml worlds/diffusion_native.yaml" THREADS="1 2" \
#     SIZES="1000x1000 5000x200" REPEAT=3 bench/whole/whole_process.sh build
# Rows: world, robots, ticks, threads, median wall seconds, robot-ticks/s.
set -eu
build=${1:-build}
root=$(cd "$(dirname "$0")/../.." && pwd)
worlds=${WORLDS:-worlds/diffusion.yaml}
threads_list=${THREADS:-"1 2"}
sizes=${SIZES:-"1000x1000 5000x200"}
repeat=${REPEAT:-3}
program="$build/swarmsim"
[ -x "$program" ] || { echo "whole_process.sh: no program at $program (build first)" >&2; exit 2; }
printf '%-36s %7s %6s %7s %9s %12s\n' world robots ticks threads wall_s robot_ticks/s
for world in $worlds; do
  [ -f "$world" ] || world="$root/$world"
  [ -f "$world" ] || { echo "whole_process.sh: no world $world" >&2; exit 2; }
  for size in $sizes; do
    robots=${size%x*}
    ticks=${size#*x}
    for threads in $threads_list; do
      times=""
      i=0
      while [ "$i" -lt "$repeat" ]; do
        start=$(date +%s.%N)
        "$program" run "$world" --set robots="$robots" --steps "$ticks" --threads "$threads" \
          --quiet > /dev/null
        end=$(date +%s.%N)
        times="$times $(awk -v a="$start" -v b="$end" 'BEGIN {print b - a}')"
        i=$((i + 1))
      done
      median=$(printf '%s\n' $times | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}')
      rate=$(awk -v r="$robots" -v t="$ticks" -v m="$median" 'BEGIN {print r * t / m}')
      printf '%-36s %7d %6d %7d %9.2f %12.0f\n' "$(basename "$world")" "$robots" "$ticks" \
        "$threads" "$median" "$rate"
    done
  done
done
