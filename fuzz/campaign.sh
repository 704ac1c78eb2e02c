#!/usr/bin/env bash
# The fuzz campaign: builds every target, then runs each in turn (one fuzzer
# process at a time, under nice) for RUNS executions, and records a row per target
# in CAMPAIGN.md as soon as it ends (between the TABLE markers; rows of targets
# not run are kept).
#
# Usage: fuzz/campaign.sh [RUNS] [TARGET...]
#   RUNS     executions per target (default 10000000)
#   TARGET   targets to run (default: all, see common.sh)
#
# Each target's growing corpus is fuzz/work/<target> (seeded from the committed
# fuzz/corpus/<target>, which is never written to); findings land in
# fuzz/artifacts/<target>/ and logs in fuzz/work/logs/. A finding stops its target
# and the script goes on with the next; the exit status is 1 if any target found
# something.
set -uo pipefail
cd "$(dirname "$0")"
source ./common.sh

RUNS=${1:-10000000}
shift || true
if [ $# -gt 0 ]; then TARGETS=("$@"); else TARGETS=("${ALL_TARGETS[@]}"); fi

ensure_cargo_fuzz || exit 2
nice -n 10 "${FUZZ_CARGO[@]}" fuzz build "${BUILD_FLAGS[@]}" || exit 2
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
mkdir -p work/logs

# Replaces (or adds) the row of target $1 in CAMPAIGN.md's table with $2.
update_table() {
    local md=CAMPAIGN.md tmp t
    if [ ! -f "$md" ] || ! grep -q '^<!-- TABLE BEGIN' "$md"; then
        printf '# Fuzz campaign\n\n<!-- TABLE BEGIN (written by campaign.sh) -->\n<!-- TABLE END -->\n' >>"$md"
    fi
    tmp=$(mktemp)
    {
        sed '/^<!-- TABLE BEGIN/q' "$md"
        echo "| target | executions | exec/s | seconds | findings | commit, date |"
        echo "|---|---:|---:|---:|---|---|"
        for t in "${ALL_TARGETS[@]}"; do
            if [ "$t" = "$1" ]; then
                echo "$2"
            else
                sed -n '/^<!-- TABLE BEGIN/,/^<!-- TABLE END/p' "$md" | grep "^| $t |" || true
            fi
        done
        sed -n '/^<!-- TABLE END/,$p' "$md"
    } >"$tmp"
    mv "$tmp" "$md"
}

status=0
for t in "${TARGETS[@]}"; do
    mkdir -p "work/$t" "artifacts/$t" "corpus/$t"
    log="work/logs/$t.log"
    before=$(ls "artifacts/$t" | wc -l)
    dict=()
    if [ -f "dict/$t.dict" ]; then dict=(-dict="dict/$t.dict"); fi
    echo "fuzz: $t, $RUNS executions" >&2
    start=$(date +%s)
    nice -n 10 "${FUZZ_CARGO[@]}" fuzz run "${BUILD_FLAGS[@]}" "$t" "work/$t" "corpus/$t" -- \
        -runs="$RUNS" "${FUZZ_LIMITS[@]}" "${dict[@]}" -print_final_stats=1 \
        -artifact_prefix="artifacts/$t/" >"$log" 2>&1
    rc=$?
    secs=$(( $(date +%s) - start ))
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    execs=${execs:-0}
    rate=$(( execs / (secs > 0 ? secs : 1) ))
    found=$(( $(ls "artifacts/$t" | wc -l) - before ))
    if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then
        status=1
        what="$found ($(ls -t "artifacts/$t" | head -1), exit $rc)"
    else
        what=0
    fi
    echo "fuzz: $t: $execs executions in ${secs}s ($rate/s), findings: $what" >&2
    update_table "$t" "| $t | $execs | $rate | $secs | $what | $commit, $(date -u +%Y-%m-%d) |"
done
exit $status
