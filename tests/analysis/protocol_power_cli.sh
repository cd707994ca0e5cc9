#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# `underfoot protocol power` answers "how many participants" for every shipped protocol (issue
# #15): a few simulations each (seconds), a power table with one row per size, the smallest-size
# sentence, the same numbers for the same seed, and clear refusals of impossible requests.
# Usage: protocol_power_cli.sh UNDERFOOT SOURCE_DIR
set -u
underfoot=$1
src=$2
fail=0
count=0
for protocol in "$src"/protocols/*.toml; do
    count=$((count + 1))
    name=$(basename "$protocol")
    args=(protocol power "$protocol" --participants 6,12 --simulations 6 --seed 3)
    if ! out=$(timeout 300 "$underfoot" "${args[@]}" --threads 1 2>/dev/null); then
        echo "FAIL $name: exit status $?"; echo "$out"; fail=1; continue
    fi
    rows=$(echo "$out" | grep -cE '^ +(6|12)  +[01]\.[0-9]{3} ')
    if [ "$rows" != 2 ]; then echo "FAIL $name: expected 2 power rows, got $rows"; echo "$out"; fail=1; fi
    if ! echo "$out" | grep -qE '^smallest .* reaching 80 % power: classic test .*; mixed model '; then
        echo "FAIL $name: no smallest-size sentence"; echo "$out"; fail=1
    fi
    again=$(timeout 300 "$underfoot" "${args[@]}" --threads 2 2>/dev/null)
    if [ -z "$again" ] || [ "$(echo "$out" | grep -v ' s on ')" != "$(echo "$again" | grep -v ' s on ')" ]; then
        echo "FAIL $name: a second run with the same seed (2 threads) differs"; fail=1
    fi
    echo "ok $name"
done
[ "$count" -ge 6 ] || { echo "FAIL: only $count protocols found in $src/protocols"; fail=1; }

# rating protocols: the clmm's power beside the t-test's and lmer's
out=$(timeout 300 "$underfoot" protocol power "$src/protocols/wading_listening.toml" --participants 6,12 \
      --simulations 6 --seed 3 --threads 1 --difference 1.5 2>/dev/null)
if ! echo "$out" | grep -q '^ordinal: clmm' || ! echo "$out" | grep -q '; ordinal model ' ||
   ! echo "$out" | grep -q 'effect: 1.5 points'; then
    echo "FAIL: wading_listening --difference: no clmm column or effect line"; echo "$out"; fail=1
else
    echo "ok rating power with the clmm"
fi
out=$(timeout 300 "$underfoot" protocol power "$src/protocols/wading_realism.toml" --participants 6 \
      --simulations 4 --seed 3 --threads 1 --odds-ratio 3 2>/dev/null)
if ! echo "$out" | grep -q 'effect: odds ratio 3 of a higher rating = 0.787 points'; then
    echo "FAIL: wading_realism --odds-ratio: no effect line"; echo "$out"; fail=1
else
    echo "ok rating power with an odds ratio"
fi
# the effect of a within-participant factor on identification, as an odds ratio
coherence="$src/tests/analysis/data/coherence_within.toml"
out=$(timeout 300 "$underfoot" protocol power "$coherence" --factor coherence --odds-ratio 0.5 \
      --baseline-correct 0.7 --participants 6,12 --simulations 6 --seed 3 --threads 1 2>/dev/null)
rows=$(echo "$out" | grep -cE '^ +(6|12)  +[01]\.[0-9]{3} ')
if [ "$rows" != 2 ] || ! echo "$out" | grep -q 'coherence coherent vs incoherent within'; then
    echo "FAIL: coherence odds ratio: expected 2 power rows"; echo "$out"; fail=1
else
    echo "ok coherence odds ratio"
fi
# the published matrices: found where the protocol names them, or in --published-dir
out=$(timeout 300 "$underfoot" protocol power "$src/protocols/tvcg2011_exp2.toml" --participants 6 \
      --simulations 4 --threads 1 --published-dir "$src/protocols/data" 2>/dev/null)
if ! echo "$out" | grep -qE '^ +6  +[01]\.[0-9]{3} '; then
    echo "FAIL: --published-dir"; echo "$out"; fail=1
else
    echo "ok --published-dir"
fi

# refusals: a clear message, non-zero status, no crash
expect_error() {
    local pattern=$1; shift
    local err
    err=$(timeout 60 "$underfoot" protocol power "$@" --simulations 2 --participants 4 2>&1 >/dev/null)
    local status=$?
    if [ $status -eq 0 ] || [ $status -ge 128 ] || ! echo "$err" | grep -q -- "$pattern"; then
        echo "FAIL: protocol power $*: status $status, expected message '$pattern', got: $err"
        fail=1
    else
        echo "ok refusal: $pattern"
    fi
}
expect_error "not a level of depth" "$src/protocols/wading_listening.toml" --levels shallow,muddy
expect_error "not a scale of protocol wading_listening" "$src/protocols/wading_listening.toml" --scale loudness
expect_error "no stimulus has this factor" "$src/protocols/wading_realism.toml" --factor depth
expect_error "within-subject" "$src/protocols/tvcg2011_exp1.toml" --groups a,b
expect_error "rates within participants" "$src/protocols/wading_interactive.toml" --groups order1
expect_error "as an odds ratio" "$src/tests/analysis/data/coherence_within.toml"
expect_error "not a level of coherence" "$src/tests/analysis/data/coherence_within.toml" --factor coherence --levels coherent,neutral --odds-ratio 2
expect_error "no stimulus of protocol" "$src/tests/analysis/data/coherence_within.toml" --factor depth --odds-ratio 2
expect_error "give the effect on identification as --odds-ratio" "$src/protocols/tvcg2011_exp1.toml" --difference 1
expect_error "cannot open\|No such\|not found\|cannot read" "$src/protocols/tvcg2011_exp2.toml" --published-dir /nonexistent
exit $fail
