#!/usr/bin/env bash
# Memory checks of the C ABI, as CI runs them:
#   1. every C test of ffi_tests/ under AddressSanitizer + UndefinedBehaviorSanitizer
#      (-fsanitize=address,undefined, no recovery, leak detection on), linked
#      against libabgs built with -Zsanitizer=address (nightly toolchain), so the
#      library's own heap and stack accesses are checked too, not only the C side;
#   2. valgrind memcheck on examples_c/pipeline.c (load -> dense grid -> sizes ->
#      simplify -> evaluate -> queries -> save -> free) over a shared model, with
#      the release library: zero errors and zero definite leaks, or it fails.
# Usage: scripts/sanitize.sh [asan|valgrind|all]   (default all)
# Needs: gcc, the nightly toolchain (rustup) for step 1, valgrind for step 2
# (installed with apt-get when missing and running as root).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
what=${1:-all}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/abgs-sanitize.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
cflags=(-std=c11 -D_POSIX_C_SOURCE=200809L -g -O1 -Wall -Wextra -Werror -Iinclude -Iffi_tests)

if [[ $what == all || $what == asan ]]; then
  echo "== ASan + UBSan: library built with -Zsanitizer=address"
  host=$(rustc -vV | sed -n 's/^host: //p')
  # Third-party crates at opt-level 0 here (the dev profile gives them 2): the
  # sanitized build compiles every dependency again, tract's crates above all.
  # Measured in two clean runs of .ci/run on 2 cores: this whole script took
  # 1,169 s with them at opt-level 2 and 521 s at 0 (library 250 s, the C
  # tests under ASan 202 s, valgrind 69 s).
  RUSTFLAGS="-Zsanitizer=address" cargo +nightly build --quiet --lib --target "$host" --target-dir target/asan \
    --config 'profile.dev.package."*".opt-level=0'
  echo "   library built in ${SECONDS} s"
  lib=target/asan/$host/debug
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1
  # Third-party leaks only, each explained in the file.
  export LSAN_OPTIONS=suppressions=$repo/scripts/lsan.supp:print_suppressions=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  failed=0
  for src in ffi_tests/*.c; do
    name=$(basename "$src" .c)
    gcc "${cflags[@]}" -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all \
      "$src" -o "$tmp/$name" -L"$lib" -labgs -Wl,-rpath,"$repo/$lib" -lpthread -lm
    if (cd "$tmp" && LD_LIBRARY_PATH="$repo/$lib" ./"$name" "$tmp" > "$tmp/$name.log" 2>&1); then
      echo "ok    $name: $(tail -1 "$tmp/$name.log")"
    else
      echo "FAIL  $name"; sed -n '1,80p' "$tmp/$name.log"; failed=1
    fi
  done
  ((failed == 0)) || { echo "sanitizer run failed"; exit 1; }
  echo "   C tests done at ${SECONDS} s"
fi

if [[ $what == all || $what == valgrind ]]; then
  echo "== valgrind memcheck: examples_c/pipeline.c on gmsh_t20_component8.stl"
  if ! command -v valgrind > /dev/null; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind > /dev/null
  fi
  [[ -f target/release/libabgs.so ]] || cargo build --release --workspace --lib
  gcc -std=c11 -O2 -g -Wall -Wextra -Werror -pedantic -Iinclude examples_c/pipeline.c \
    -Ltarget/release -labgs -Wl,-rpath,"$repo/target/release" -o "$tmp/pipeline"
  model=../shared/meshes/gmsh_t20_component8.stl
  [[ -f $model ]] || { echo "missing $model: ../shared must be beside the checkout"; exit 1; }
  # A coarse dense grid (diagonal / 20) keeps the run to a few minutes under valgrind.
  RAYON_NUM_THREADS=2 valgrind --error-exitcode=3 --leak-check=full --errors-for-leak-kinds=definite \
    --show-leak-kinds=definite "$tmp/pipeline" "$model" "$tmp/t20.vtk" 0.05 > "$tmp/valgrind.log" 2>&1 \
    || { tail -60 "$tmp/valgrind.log"; echo "valgrind found errors or definite leaks"; exit 1; }
  grep -E "ERROR SUMMARY|definitely lost|simplified:" "$tmp/valgrind.log"
fi
