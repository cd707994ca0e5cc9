#!/usr/bin/env bash
# The engine's kernels are chosen at run time (AVX where the CPU has it, else SSE2) and
# must give the same samples bit for bit. Renders every bundled surface twice, once limited to
# SSE2 (UNDERFOOT_SIMD=sse2) and once with the CPU's best kernels, as 32-bit float WAV, and
# compares the files byte for byte. Also checks that an unknown UNDERFOOT_SIMD value is refused.
#   simd_identical.sh <underfoot> <work dir>
set -uo pipefail
underfoot="$(readlink -f "$1")"
work="$2"
rm -rf "$work" && mkdir -p "$work/best" "$work/sse2" || exit 1
"$underfoot" render --all --seconds 3 --seed 11 --format float -q -o "$work/best" || exit 1
UNDERFOOT_SIMD=sse2 "$underfoot" render --all --seconds 3 --seed 11 --format float -q \
    -o "$work/sse2" || exit 1
n=0 fail=0
for f in "$work"/best/*.wav; do
    n=$((n + 1))
    if ! cmp -s "$f" "$work/sse2/$(basename "$f")"; then
        echo "DIFFERENT: $(basename "$f") (SSE2 kernels against the CPU's best)"
        fail=1
    fi
done
[ "$n" -ge 18 ] || { echo "expected every bundled surface, rendered $n"; exit 1; }
echo "$n surfaces: SSE2 and the CPU's best kernels give identical files"
if UNDERFOOT_SIMD=avx9 "$underfoot" surfaces >/dev/null 2>"$work/err.txt"; then
    echo "an unknown UNDERFOOT_SIMD value was accepted"
    fail=1
elif ! grep -q "UNDERFOOT_SIMD" "$work/err.txt"; then
    echo "the refusal does not name UNDERFOOT_SIMD: $(cat "$work/err.txt")"
    fail=1
fi
exit $fail
