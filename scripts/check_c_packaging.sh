#!/usr/bin/env bash
# Checks the C packaging of abgs end to end:
#   (i)   examples_c/query_basic.c built with the one-line cc command in its
#         header comment (plus -Wall -Wextra -Werror -pedantic) and run;
#   (ii)  examples_c built with CMake against the source-tree config
#         (-Dabgs_DIR=<repo>/cmake), plus the version and not-built checks;
#   (iii) scripts/install.sh into a temporary prefix, then examples_c built with
#         CMake (-DCMAKE_PREFIX_PATH, shared and static) and with pkg-config.
# Each program is run on a tiny grid with sizes (a VTK unit square) and its
# answers are compared with the expected interpolated sizes.
# Usage: scripts/check_c_packaging.sh   (KEEP_TMP=1 keeps the temporary directory)
# Builds target/release/libabgs.{so,a} with cargo only if they are missing.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/abgs-c-packaging.XXXXXX")
cleanup() {
  local rc=$?
  if [[ ${KEEP_TMP:-0} == 1 || $rc -ne 0 ]]; then
    echo "(temporary files kept in $tmp)"
  else
    rm -rf "$tmp"
  fi
  if [[ $rc -ne 0 ]]; then
    echo "FAILED (exit $rc)" >&2
  fi
}
trap cleanup EXIT

step() { printf '\n==> %s\n' "$*"; }
fail() { echo "check_c_packaging: $*" >&2; exit 1; }
run() { printf '+ %s\n' "$*"; "$@"; }

# --- tools -------------------------------------------------------------------
step "tools"
missing=()
command -v cmake >/dev/null || missing+=(cmake)
command -v pkg-config >/dev/null || missing+=(pkg-config)
if ((${#missing[@]})); then
  if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
    run apt-get update
    run apt-get install -y "${missing[@]}"
  else
    fail "missing ${missing[*]}: install them (apt-get install -y ${missing[*]})"
  fi
fi
cc_bin=${CC:-cc}
command -v "$cc_bin" >/dev/null || fail "no C compiler ($cc_bin)"
echo "cc: $(command -v "$cc_bin"); $(cmake --version | head -1); pkg-config $(pkg-config --version)"

# --- library -----------------------------------------------------------------
step "library"
if [[ ! -f $repo/target/release/libabgs.so || ! -f $repo/target/release/libabgs.a ]]; then
  # Features unified over the workspace, as scripts/install.sh builds.
  (cd "$repo" && run cargo build --release --workspace --lib)
fi
ls -l "$repo/target/release/libabgs.so" "$repo/target/release/libabgs.a"

# --- test grid ---------------------------------------------------------------
# Unit square z=0, triangles (0 1 2) and (0 2 3), sizes 0.1 0.2 0.3 0.4 at the
# corners (0,0) (1,0) (1,1) (0,1).
step "test grid"
grid=$tmp/square.vtk
cat > "$grid" <<'VTK'
# vtk DataFile Version 3.0
abgs check_c_packaging unit square
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 4 double
0 0 0
1 0 0
1 1 0
0 1 0
CELLS 2 8
3 0 1 2
3 0 2 3
CELL_TYPES 2
5
5
POINT_DATA 4
SCALARS size double 1
LOOKUP_TABLE default
0.1
0.2
0.3
0.4
VTK
echo "wrote $grid"

# Query points and the sizes they must get: corners 0 and 2; the centre seen
# from above (on the shared edge 0-2); a point below the midpoint of edge 1-2;
# (0.75 0.25) inside triangle (0 1 2), barycentrics (0.25 0.5 0.25).
points=(0 0 0   1 1 0   0.5 0.5 1   1 0.5 -2   0.75 0.25 0)
expected=(0.1 0.3 0.2 0.25 0.2)

# check_output FILE: the program's stdout must list every point twice (plain
# and hinted) with the expected sizes, and the default run must give 5+5 lines.
check_output() {
  local out=$1
  grep -q '^  vertices 4, triangles 2, bodies 1$' "$out" || fail "unexpected stats in $out"
  grep -q '^  sizes 0.1 to 0.4$' "$out" || fail "unexpected size range in $out"
  awk -v want="${expected[*]}" '
    BEGIN { n = split(want, w, " ") }
    /^sizes \(/ { pass++; i = 0; next }
    pass >= 1 && NF == 4 && $1 ~ /^[-0-9.e+]+$/ {
      i++
      if (i > n || ($4 - w[i]) > 1e-12 || (w[i] - $4) > 1e-12) {
        printf "bad size %s at point %d (%s %s %s), expected %s\n", $4, i, $1, $2, $3, w[i] > "/dev/stderr"
        bad = 1
      }
      count[pass]++
    }
    END { if (bad || pass != 2 || count[1] != n || count[2] != n) exit 1 }
  ' "$out" || fail "wrong sizes in $out"
}

# run_example BINARY: runs it with the points, with none, and on a missing file.
run_example() {
  local bin=$1 name
  name=$(basename "$bin")
  run "$bin" "$grid" "${points[@]}" | tee "$tmp/$name.out"
  check_output "$tmp/$name.out"
  run "$bin" "$grid" > "$tmp/$name.default.out"
  [[ $(grep -c '^[-0-9.e+]* [-0-9.e+]* [-0-9.e+]* [-0-9.e+]*$' "$tmp/$name.default.out") -eq 10 ]] \
    || fail "$name without points did not print 2 x 5 sizes"
  if "$bin" "$tmp/no-such-grid.vtk" > /dev/null 2> "$tmp/$name.err"; then
    fail "$name succeeded on a missing file"
  fi
  grep -q 'abgs_grid_load failed: ABGS_ERR_IO' "$tmp/$name.err" || {
    cat "$tmp/$name.err" >&2
    fail "$name did not report the load error"
  }
  if grep -q '^warning:' "$tmp/$name.out"; then fail "$name warned of a version mismatch"; fi
  echo "ok: $name (points, default points, error path)"
}

# --- (i) the one-line cc command ---------------------------------------------
step "(i) cc command from examples_c/query_basic.c"
cc_line=$(sed -n 's/^ \*   \(cc .*\)$/\1/p' "$repo/examples_c/query_basic.c" | head -1)
[[ -n $cc_line ]] || fail "no cc command in the header comment of examples_c/query_basic.c"
[[ $cc_line == *" -o query_basic" ]] || fail "the cc command should end in -o query_basic"
echo "command in the comment: $cc_line"
# Same command, run from the repository root, output in $tmp, warnings fatal.
cc_cmd="${cc_line% -o query_basic} -Wall -Wextra -Werror -pedantic -o \"$tmp/query_basic\""
[[ $cc_bin == cc ]] || cc_cmd="$cc_bin ${cc_cmd#cc }"
(cd "$repo" && echo "+ $cc_cmd" && eval "$cc_cmd")
run_example "$tmp/query_basic"
if command -v clang >/dev/null; then
  (cd "$repo" && run clang -std=c11 -O2 -Wall -Wextra -Werror -pedantic -Iinclude \
    examples_c/query_basic.c -Ltarget/release -labgs -Wl,-rpath,"$repo/target/release" \
    -o "$tmp/query_basic_clang")
  run_example "$tmp/query_basic_clang"
fi

# --- (ii) CMake, source-tree config -------------------------------------------
step "(ii) CMake with -Dabgs_DIR=$repo/cmake"
run cmake -S "$repo/examples_c" -B "$tmp/build-src" -Dabgs_DIR="$repo/cmake" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS="-Wall -Wextra -Werror" -DQUERY_BASIC_STATIC=ON
run cmake --build "$tmp/build-src"
run_example "$tmp/build-src/query_basic"
run_example "$tmp/build-src/query_basic_static"
if grep -q libabgs <<<"$(ldd "$tmp/build-src/query_basic_static")"; then
  fail "query_basic_static depends on libabgs.so"
fi
grep -q 'NEEDED.*\[libabgs.so\]' <<<"$(readelf -d "$tmp/build-src/query_basic")" \
  || fail "query_basic does not record libabgs.so as a plain NEEDED entry"

# find_package version rules and the not-built message, on throw-away projects.
probe() { # probe NAME VERSION_ARGS CMAKE_ARGS...: configures find_package(abgs VERSION_ARGS)
  local name=$1 vargs=$2
  shift 2
  mkdir -p "$tmp/probe-$name"
  printf 'cmake_minimum_required(VERSION 3.19)\nproject(p LANGUAGES C)\nfind_package(abgs %s REQUIRED)\nmessage(STATUS "abgs_VERSION=${abgs_VERSION}")\n' \
    "$vargs" > "$tmp/probe-$name/CMakeLists.txt"
  cmake -S "$tmp/probe-$name" -B "$tmp/probe-$name/build" "$@" > "$tmp/probe-$name.log" 2>&1
}
version=$(sed -n 's/^#define ABGS_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)$/\2/p' "$repo/include/abgs.h" | paste -sd.)
echo "header version: $version"
major=${version%%.*} minor=${version#*.}; minor=${minor%%.*}
for req in "$major.$minor" "$version" "$version EXACT" "$major.$minor...$((major + 1)).0"; do
  probe ok "$req" -Dabgs_DIR="$repo/cmake" || { cat "$tmp/probe-ok.log"; fail "find_package(abgs $req) failed"; }
  grep -q "abgs_VERSION=$version" "$tmp/probe-ok.log" || fail "find_package(abgs $req): wrong abgs_VERSION"
  echo "ok: find_package(abgs $req) accepts $version"
done
if [[ $major == 0 ]]; then
  bad_reqs=("0.$((minor + 1))")
  ((minor > 0)) && bad_reqs+=("0.$((minor - 1))")
else
  bad_reqs=("$((major + 1)).0" "$((major - 1)).0")
fi
for req in "${bad_reqs[@]}"; do
  if probe bad "$req" -Dabgs_DIR="$repo/cmake"; then fail "find_package(abgs $req) accepted $version"; fi
  echo "ok: find_package(abgs $req) rejects $version"
done
if probe notbuilt "$major.$minor" -Dabgs_DIR="$repo/cmake" -DABGS_LIBRARY_DIR="$tmp/nowhere"; then
  fail "find_package(abgs) succeeded without a library"
fi
grep -q 'libabgs.so is not built' "$tmp/probe-notbuilt.log" \
  || { cat "$tmp/probe-notbuilt.log"; fail "no clear message when the library is not built"; }
echo "ok: a missing library is reported:"
grep -A3 'libabgs.so is not built' "$tmp/probe-notbuilt.log" | sed 's/^/    /'

# --- (iii) install, then CMake and pkg-config against the prefix --------------
step "(iii) scripts/install.sh $tmp/prefix"
prefix=$tmp/prefix
# The library under test is the one just checked: no rebuild here.
ABGS_NO_BUILD=1 run "$repo/scripts/install.sh" "$prefix"
for f in lib/libabgs.so lib/libabgs.a include/abgs.h lib/cmake/abgs/abgsConfig.cmake \
  lib/cmake/abgs/abgsConfigVersion.cmake lib/pkgconfig/abgs.pc; do
  [[ -f $prefix/$f ]] || fail "install.sh did not install $f"
done

step "(iii) CMake with -DCMAKE_PREFIX_PATH=$prefix"
run cmake -S "$repo/examples_c" -B "$tmp/build-inst" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS="-Wall -Wextra -Werror" -DQUERY_BASIC_STATIC=ON \
  | tee "$tmp/build-inst.log"
grep -q "abgs_DIR:PATH=$prefix/lib/cmake/abgs" "$tmp/build-inst/CMakeCache.txt" \
  || fail "CMake did not use the installed config"
run cmake --build "$tmp/build-inst"
run_example "$tmp/build-inst/query_basic"
run_example "$tmp/build-inst/query_basic_static"
# (ldd into a variable first: `ldd | grep -q` can fail under pipefail when grep exits early.)
deps=$(ldd "$tmp/build-inst/query_basic")
grep -q "$prefix/lib/libabgs.so" <<<"$deps" \
  || { echo "$deps"; fail "the CMake build does not load $prefix/lib/libabgs.so"; }
# The installed version file must not depend on the source tree.
probe inst "$major.$minor" -DCMAKE_PREFIX_PATH="$prefix" \
  || { cat "$tmp/probe-inst.log"; fail "installed find_package(abgs $major.$minor) failed"; }
grep -q "abgs_VERSION=$version" "$tmp/probe-inst.log" || fail "installed config: wrong abgs_VERSION"
if probe instbad "0.$((minor + 1))" -DCMAKE_PREFIX_PATH="$prefix"; then
  fail "installed config accepted 0.$((minor + 1))"
fi
echo "ok: installed config version checks"

step "(iii) pkg-config with PKG_CONFIG_PATH=$prefix/lib/pkgconfig"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
run pkg-config --modversion abgs
[[ $(pkg-config --modversion abgs) == "$version" ]] || fail "abgs.pc has the wrong version"
pc_flags=$(pkg-config --cflags --libs abgs)
echo "pkg-config --cflags --libs abgs: $pc_flags"
echo "pkg-config --static --libs abgs: $(pkg-config --static --libs abgs)"
# shellcheck disable=SC2086 # the flags are meant to be split
run "$cc_bin" -std=c11 -O2 -Wall -Wextra -Werror -pedantic "$repo/examples_c/query_basic.c" \
  $pc_flags -o "$tmp/query_basic_pc"
LD_LIBRARY_PATH="$prefix/lib" run_example "$tmp/query_basic_pc"
deps=$(LD_LIBRARY_PATH="$prefix/lib" ldd "$tmp/query_basic_pc")
grep -q "$prefix/lib/libabgs.so" <<<"$deps" \
  || fail "the pkg-config build does not load $prefix/lib/libabgs.so"
# libabgs.a with the private libraries (-l:libabgs.a picks the archive).
pc_static=$(pkg-config --static --libs abgs | sed 's/-labgs/-l:libabgs.a/')
# shellcheck disable=SC2086
run "$cc_bin" -std=c11 -O2 -Wall -Wextra -Werror -pedantic $(pkg-config --cflags abgs) \
  "$repo/examples_c/query_basic.c" $pc_static -o "$tmp/query_basic_pc_static"
if grep -q libabgs <<<"$(ldd "$tmp/query_basic_pc_static")"; then
  fail "query_basic_pc_static depends on libabgs.so"
fi
run_example "$tmp/query_basic_pc_static"

step "all C packaging checks passed"
