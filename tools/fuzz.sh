#!/usr/bin/env bash
# Runs libFuzzer on one harness (tools/fuzz/README.md):
#
#   tools/fuzz.sh TARGET SECONDS [SEED_FOLDER...]
#
# Configures and builds the fuzz preset (build-fuzz/, clang + ASan) if
# needed, gathers TARGET's seeds (tools/fuzz/targets.txt, tests/data/fuzz/
# TARGET/ and any SEED_FOLDER given, e.g. a folder of URDFs elsewhere) into
# build-fuzz/seeds/TARGET, and fuzzes for SECONDS on one core with the
# working corpus build-fuzz/corpus/TARGET (kept between runs: a second run
# goes on from the first). Crash, leak, timeout and out-of-memory inputs land
# in build-fuzz/artifacts/TARGET/. Prints executions, coverage, corpus size
# and the slowest input of the corpus.
#
# tests/data/fuzz/TARGET/crashes/ (past crash inputs, replayed by the test
# suite) are not seeds here: one not fixed yet would stop every run.
#
#   tools/fuzz.sh list          # the targets
#   FUZZ_ARGS='-only_ascii=1' tools/fuzz.sh lua 600   # more libFuzzer flags
#   FUZZ_KEEP_GOING=1 tools/fuzz.sh recording 600     # go on past findings
#                  # (-fork=1: one child at a time; each finding saved)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
targets_file="$root/tools/fuzz/targets.txt"
targets() { grep -E '^[a-z]' "$targets_file" | awk '{print $1}'; }

if [ $# -ge 1 ] && [ "$1" = list ]; then targets; exit 0; fi
if [ $# -lt 2 ] || ! [[ "$2" =~ ^[0-9]+$ ]]; then
  echo "usage: tools/fuzz.sh TARGET SECONDS [SEED_FOLDER...]   (targets: $(targets | tr '\n' ' '))" >&2
  exit 2
fi
target="$1" seconds="$2"
shift 2
line="$(grep -E "^$target[[:space:]]" "$targets_file" || true)"
if [ -z "$line" ]; then
  echo "tools/fuzz.sh: no target '$target' (targets: $(targets | tr '\n' ' '))" >&2
  exit 2
fi
read -r _ max_len timeout rss flags seeds <<<"$line"
[ "$flags" = - ] && flags="" || flags="${flags//,/ }"

# clang and libFuzzer's runtime (Debian: clang, libclang-rt-14-dev).
if ! command -v clang++ >/dev/null 2>&1; then
  echo "tools/fuzz.sh: clang++ is missing: apt-get install clang libclang-rt-14-dev" >&2
  exit 1
fi
if ! echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' |
    clang++ -x c++ -fsanitize=fuzzer -o /dev/null - >/dev/null 2>&1; then
  echo "tools/fuzz.sh: clang cannot link libFuzzer: apt-get install libclang-rt-14-dev" >&2
  exit 1
fi

build="$root/build-fuzz"
cd "$root"
[ -f "$build/build.ninja" ] || cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target "fuzz_$target" | grep -v '^ninja: no work to do' || true
program="$build/fuzz/fuzz_$target"

# The seeds: files of the source tree (targets.txt), filtered by extension.
seed_dir="$build/seeds/$target"
rm -rf "$seed_dir"
mkdir -p "$seed_dir" "$build/corpus/$target" "$build/artifacts/$target"
ext=""
n=0
for word in $seeds; do
  if [ "$word" = --ext ]; then ext=next; continue; fi
  if [ "$ext" = next ]; then ext="$word"; continue; fi
  [ "$word" = --any ] && { ext=""; continue; }
  while IFS= read -r -d '' f; do
    name="$(basename "$f")"
    if [ -n "$ext" ] && ! [[ ",$ext," == *",.${name##*.},"* ]]; then continue; fi
    n=$((n + 1))
    cp "$f" "$seed_dir/$n-$name"
  done < <(find "$root/$word" -type f -size -"$max_len"c -print0 2>/dev/null)
done
while IFS= read -r -d '' f; do
  n=$((n + 1))
  cp "$f" "$seed_dir/$n-$(basename "$f")"
done < <(find "$root/tests/data/fuzz/$target" -path '*/crashes' -prune -o -type f -print0 2>/dev/null)
# Extra folders: files of the target's extensions (all files for those without).
for folder in "$@"; do
  while IFS= read -r -d '' f; do
    name="$(basename "$f")"
    if [ -n "$ext" ] && ! [[ ",$ext," == *",.${name##*.},"* ]]; then continue; fi
    n=$((n + 1))
    cp "$f" "$seed_dir/$n-$name"
  done < <(find "$folder" -type f -size -"$max_len"c -print0)
done

echo "tools/fuzz.sh: fuzz_$target for $seconds s (seeds: $n from the tree, tests/data/fuzz/$target;" \
     "corpus: build-fuzz/corpus/$target)"
log="$build/artifacts/$target/last-run.log"
status=0
# One core (no -jobs/-workers); -fork=0. -max_total_time also bounds a
# stuck run: libFuzzer's own -timeout reports an input slower than TIMEOUT s.
# Third-party leaks we cannot fix (tools/fuzz/lsan.supp says which).
export LSAN_OPTIONS="suppressions=$root/tools/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
keep_going=()
if [ -n "${FUZZ_KEEP_GOING:-}" ]; then
  keep_going=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
"$program" "$build/corpus/$target" "$seed_dir" ${keep_going[@]+"${keep_going[@]}"} \
  -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb="$rss" -max_len="$max_len" \
  -artifact_prefix="$build/artifacts/$target/" -print_final_stats=1 $flags ${FUZZ_ARGS:-} \
  >"$log" 2>&1 || status=$?

# The figures.
last="$(grep -E '^#[0-9]+:?[[:space:]]' "$log" | tail -n 1 || true)"
echo "$last"
execs="$(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}' | tail -n 1 || true)"
[ -n "$execs" ] || execs="$(echo "$last" | sed -nE 's/^#([0-9]+).*/\1/p')"
cov="$(echo "$last" | sed -nE 's/.*cov: ([0-9]+).*ft: ([0-9]+).*/\1 edges, \2 features/p')"
if [ -n "${FUZZ_KEEP_GOING:-}" ]; then
  echo "findings:     $(echo "$last" | sed -nE 's|.*oom/timeout/crash: ([0-9/]+).*|\1 (oom/timeout/crash)|p')"
fi
files="$(find "$build/corpus/$target" -type f | wc -l)"
bytes="$(du -sb "$build/corpus/$target" | awk '{print $1}')"
# The slowest input: every corpus file once more, timed by libFuzzer.
slowest="$(find "$build/corpus/$target" -type f -print0 |
  xargs -0 -r -n 500 "$program" -runs=1 -rss_limit_mb="$rss" -timeout="$timeout" 2>&1 |
  sed -nE 's/^Executed (.*) in ([0-9]+) ms$/\2 \1/p' | sort -n | tail -n 1)"
echo "executions:   ${execs:-?} in this run"
echo "coverage:     ${cov:-?}"
echo "corpus:       $files inputs, $bytes bytes (build-fuzz/corpus/$target)"
echo "slowest:      ${slowest%% *} ms (${slowest#* })"
if [ "$status" -ne 0 ]; then
  echo "FINDING (libFuzzer exit $status): see $log; the input is in build-fuzz/artifacts/$target/:"
  grep -E '^(==[0-9]+==ERROR|SUMMARY|artifact_prefix|Test unit written|.*Test unit written)' "$log" | head -n 5 || true
  ls -t "$build/artifacts/$target" | grep -v last-run.log | head -n 3
  exit 1
fi
