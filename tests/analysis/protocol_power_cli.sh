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
exit $fail
