# Shared by campaign.sh and smoke.sh (sourced, not run).

# The targets, in campaign order.
ALL_TARGETS=(stl_ascii stl_binary obj off ply msh22 msh41 vtk vtu medit arrays_query deserialize)

# Build configuration: release with debug assertions and overflow checks, no
# sanitizer (abgs has no `unsafe` outside src/ffi), no comparison tracing (half
# of the time per input; the keywords it would discover come from the seeds and
# the dictionaries in dict/); see README.md.
BUILD_FLAGS=(-O -a -s none --no-trace-compares)

# libFuzzer limits: a finding is a crash, an input taking over 1 s, over 2 GiB of
# RSS (a single allocation over 2 GiB aborts in src/alloc_limit.rs).
FUZZ_LIMITS=(-timeout=1 -rss_limit_mb=2048 -max_len=65536)

# The cargo-fuzz version the scripts are written against.
CARGO_FUZZ_VERSION=0.13.2

# The cargo command for fuzzing: the nightly toolchain when it is installed, else
# the default toolchain with RUSTC_BOOTSTRAP=1 (without a sanitizer, cargo-fuzz
# needs nothing more from nightly: checked with stable 1.95), so that the smoke
# run also works on a machine that has only the stable toolchain.
if cargo +nightly --version >/dev/null 2>&1; then
    FUZZ_CARGO=(cargo +nightly)
else
    FUZZ_CARGO=(env RUSTC_BOOTSTRAP=1 cargo)
fi

# Installs cargo-fuzz (pinned) when missing.
ensure_cargo_fuzz() {
    if ! cargo fuzz --version 2>/dev/null | grep -q "$CARGO_FUZZ_VERSION"; then
        echo "fuzz: installing cargo-fuzz $CARGO_FUZZ_VERSION" >&2
        cargo install cargo-fuzz --locked --version "$CARGO_FUZZ_VERSION" || return 1
    fi
}
