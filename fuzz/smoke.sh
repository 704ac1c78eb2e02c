#!/usr/bin/env bash
# CI smoke run: builds every fuzz target, then runs each for a few seconds over its
# committed seed corpus (about 10 s each, under 2 minutes of fuzzing in all; the
# build is not counted). New inputs go to a temporary directory, never to the
# committed corpus. Exits non-zero on any crash, hang or out-of-memory.
#
# Usage: fuzz/smoke.sh [SECONDS_PER_TARGET]   (default 10)
set -uo pipefail
cd "$(dirname "$0")"
source ./common.sh

SECS=${1:-10}
ensure_cargo_fuzz || exit 2
nice -n 10 "${FUZZ_CARGO[@]}" fuzz build "${BUILD_FLAGS[@]}" || exit 2

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
start=$(date +%s)
for t in "${ALL_TARGETS[@]}"; do
    mkdir -p "$tmp/$t" "corpus/$t"
    # The regression inputs first (each must pass), then fuzzing from the seeds.
    if [ -d "regressions/$t" ] && [ -n "$(ls "regressions/$t")" ]; then
        if ! "${FUZZ_CARGO[@]}" fuzz run "${BUILD_FLAGS[@]}" "$t" "regressions/$t" -- \
            -runs=0 "${FUZZ_LIMITS[@]}" >"$tmp/$t.regressions.log" 2>&1; then
            echo "smoke: $t: a regression input fails again:" >&2
            tail -40 "$tmp/$t.regressions.log" >&2
            fail=1
        fi
    fi
    dict=()
    if [ -f "dict/$t.dict" ]; then dict=(-dict="dict/$t.dict"); fi
    if nice -n 10 "${FUZZ_CARGO[@]}" fuzz run "${BUILD_FLAGS[@]}" "$t" "$tmp/$t" "corpus/$t" -- \
        -max_total_time="$SECS" "${FUZZ_LIMITS[@]}" "${dict[@]}" -print_final_stats=1 \
        -artifact_prefix="$tmp/$t-" >"$tmp/$t.log" 2>&1; then
        n=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$tmp/$t.log" | grep -o '[0-9]*$' | tail -1)
        echo "smoke: $t ok (${n:-?} executions)"
    else
        echo "smoke: $t FAILED:" >&2
        tail -60 "$tmp/$t.log" >&2
        fail=1
    fi
done
echo "smoke: $(( $(date +%s) - start )) s of fuzzing for ${#ALL_TARGETS[@]} targets"
exit $fail
