#!/usr/bin/env bash
# A fuzz campaign outside the default test run: every libFuzzer target (or the ones named) for
# SECONDS each, through run_fuzz.sh (regression inputs first, then fuzzing from the seed corpus),
# at most JOBS at a time, then a table of executions, coverage and findings per target.
#   bash tests/fuzz/run_campaign.sh SECONDS [target ...]      # e.g. 300 rating_model clip_manifest
# Environment: BUILD (default build-fuzz, configured with -DUNDERFOOT_FUZZ=ON and built with
# --target underfoot_fuzz), JOBS (default 1; the machine is shared), WORK (default
# $BUILD/tests/fuzz/campaign). Exit status 1 when any target has a finding; its input is left
# in $WORK/<target>/artifacts/ (add it to tests/fuzz/regressions/<target>/ with the fix).
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
seconds="${1:?usage: run_campaign.sh SECONDS [target ...]}"
shift
case "$seconds" in '' | *[!0-9]*) echo "SECONDS must be a whole number, got '$seconds'" >&2; exit 2 ;; esac
build="${BUILD:-$root/build-fuzz}"
jobs="${JOBS:-1}"
work="${WORK:-$build/tests/fuzz/campaign}"
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for source in "$here"/fuzz_*.cpp; do
    name="$(basename "$source" .cpp)"
    targets+=("${name#fuzz_}")
  done
fi
for t in "${targets[@]}"; do
  if [ ! -x "$build/tests/fuzz/fuzz_$t" ]; then
    echo "no target $build/tests/fuzz/fuzz_$t (build it: cmake --build $build --target underfoot_fuzz)" >&2
    exit 2
  fi
done
mkdir -p "$work"
echo "== campaign: ${#targets[@]} target(s), $seconds s each, $jobs at a time, work in $work"
start=$(date +%s)
run_one() {
  local t="$1"
  bash "$here/run_fuzz.sh" "$build/tests/fuzz/fuzz_$t" "$here/corpus/$t" "$here/regressions/$t" \
    "$seconds" "$work/$t" > "$work/$t.log" 2>&1
  echo $? > "$work/$t.status"
}
running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait
failed=0
printf '%-22s %8s %12s %7s %7s %8s  %s\n' target seconds executions cov ft rss_mb findings
for t in "${targets[@]}"; do
  log="$work/$t/fuzz.log"
  # libFuzzer prints its final stats once, or twice after a finding: the last ones count.
  execs=$(grep -E '^stat::number_of_executed_units:' "$log" 2>/dev/null | tail -1 | awk '{print $2}')
  rss=$(grep -E '^stat::peak_rss_mb:' "$log" 2>/dev/null | tail -1 | awk '{print $2}')
  last=$(grep -E '^#[0-9]+' "$log" 2>/dev/null | tail -1)
  cov=$(echo "$last" | grep -oE 'cov: [0-9]+' | awk '{print $2}')
  ft=$(echo "$last" | grep -oE 'ft: [0-9]+' | awk '{print $2}')
  status=$(cat "$work/$t.status" 2>/dev/null || echo 1)
  if [ "$status" = 0 ]; then
    found=0
  else
    failed=1
    found="FINDING: $(ls "$work/$t/artifacts" 2>/dev/null | tr '\n' ' ')(log: $work/$t.log)"
  fi
  printf '%-22s %8s %12s %7s %7s %8s  %s\n' "$t" "$seconds" "${execs:--}" "${cov:--}" "${ft:--}" \
    "${rss:--}" "$found"
done
echo "== campaign done in $(( $(date +%s) - start )) s"
exit $failed
