#!/usr/bin/env bash
# Runs one libFuzzer target: replays every regression input (each must pass), then fuzzes from
# the seed corpus for a bounded time. A finding leaves its input in <work>/artifacts/ and fails.
#   run_fuzz.sh <target> <seed corpus dir> <regressions dir> <seconds> <work dir>
set -uo pipefail
target="$1" corpus="$2" regressions="$3" seconds="$4" work="$5"
rm -rf "$work" && mkdir -p "$work/corpus" "$work/artifacts" || exit 1
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}:abort_on_error=1:allocator_may_return_null=0"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}:halt_on_error=1"
# Bounds of one input: 10 s of work, 2 GB of memory (a bigger allocation is a finding).
common=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 -artifact_prefix="$work/artifacts/")
if [ -d "$regressions" ] && [ -n "$(ls -A "$regressions" 2>/dev/null)" ]; then
  n=$(ls -A "$regressions" | wc -l)
  echo "== replaying $n regression input(s) from $regressions"
  "$target" "${common[@]}" "$regressions"/* > "$work/replay.log" 2>&1 || {
    tail -60 "$work/replay.log"; echo "FAIL: a regression input fails again"; exit 1; }
fi
seeds=()
maxlen=65536
if [ -d "$corpus" ]; then
  seeds=("$corpus")
  biggest=$(find "$corpus" -type f -printf '%s\n' | sort -n | tail -1)
  [ -n "$biggest" ] && [ "$biggest" -gt "$maxlen" ] && maxlen=$biggest
fi
echo "== fuzzing $(basename "$target") for $seconds s"
"$target" "${common[@]}" -max_total_time="$seconds" -print_final_stats=1 -max_len="$maxlen" \
  "$work/corpus" "${seeds[@]}" > "$work/fuzz.log" 2>&1
status=$?
grep -E "^#[0-9]+.*(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss_mb" "$work/fuzz.log" | tail -4
if [ $status != 0 ]; then
  tail -80 "$work/fuzz.log"
  echo "FAIL: finding(s) in $work/artifacts/: $(ls "$work/artifacts")"
  exit 1
fi
exit 0
