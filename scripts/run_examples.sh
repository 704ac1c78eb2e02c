#!/usr/bin/env bash
# Builds every C example in examples_c/ against the INSTALLED abgs and runs it:
#   1. installs what is missing (as root, with apt: cmake, a C compiler,
#      pkg-config, openmpi-bin + libopenmpi-dev, python3-venv and the X/GL
#      libraries the Gmsh wheel links to) and gmsh==4.15.2 (pip) into a venv;
#   2. scripts/install.sh PREFIX (its `cargo build --release --workspace --lib` is a no-op
#      when the library is built; ABGS_NO_BUILD=1 skips it);
#   3. builds the examples twice: with CMake through find_package(abgs)
#      (-DCMAKE_PREFIX_PATH=PREFIX, -DGMSH_ROOT=venv), and with one cc / mpicc
#      line each from `pkg-config --cflags --libs abgs`;
#   4. runs them, from both builds, on a shared model (STL + STEP):
#        pipeline MODEL.stl coarse.abgs 0.02   STL -> dense grid -> sizes -> LBO-ABGS,
#                                              saved as .abgs (the two builds' files
#                                              must be byte-identical)
#        query_basic coarse.abgs               loads the .abgs, queries it
#        mpirun -np 2 mpi_sizing MODEL.stl     rank 0 sizes, broadcasts the bytes, both
#                                              ranks query, answers checked bit for bit
#        gmsh_size_callback MODEL.step coarse.abgs 2
#                                              Gmsh meshes the STEP, abgs as its size
#                                              callback, 2 threads
# Usage: scripts/run_examples.sh [MODEL]   (../shared/meshes/MODEL.stl and .step;
#                                           default gmsh_t20_component8)
# Environment:
#   ABGS_EXAMPLES_DIR  work folder: prefix, builds, outputs (default target/examples)
#   ABGS_GMSH_VENV     venv holding gmsh==4.15.2 (default target/harness/venv, the
#                      one bench/paper_tables.sh uses, so it is installed once)
#   ABGS_NO_BUILD=1    install the existing target/release library as it is
# Exit status: 0 when every example built, ran and passed its checks.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
model=${1:-gmsh_t20_component8}
meshes=$repo/../shared/meshes
work=${ABGS_EXAMPLES_DIR:-$repo/target/examples}
venv=${ABGS_GMSH_VENV:-$repo/target/harness/venv}
for f in "$meshes/$model.stl" "$meshes/$model.step"; do
  [[ -f $f ]] || { echo "run_examples: $f is missing" >&2; exit 2; }
done
mkdir -p "$work"
work=$(cd "$work" && pwd)
prefix=$work/prefix
start=$(date +%s)

step() { printf '\n== [%d s] %s\n' "$(($(date +%s) - start))" "$*"; }
run() { printf '+ %s\n' "$*"; "$@"; }
fail() { echo "run_examples: $*" >&2; exit 1; }
apt_install() {
  if [[ $(id -u) -ne 0 ]] || ! command -v apt-get >/dev/null; then
    fail "missing: $*; install them (apt-get install -y $*)"
  fi
  echo "installing $*"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

# --- 1. dependencies -------------------------------------------------------------
step "dependencies"
need=()
command -v cmake >/dev/null || need+=(cmake)
command -v cc >/dev/null || need+=(gcc)
command -v pkg-config >/dev/null || need+=(pkg-config)
command -v python3 >/dev/null || need+=(python3 python3-venv)
command -v mpirun >/dev/null || need+=(openmpi-bin)
# mpicc alone (openmpi-bin) cannot compile without mpi.h (libopenmpi-dev).
if ! printf '#include <mpi.h>\nint main(void){return 0;}\n' | mpicc -x c - -o /dev/null >/dev/null 2>&1; then
  need+=(libopenmpi-dev)
fi
((${#need[@]} == 0)) || apt_install "${need[@]}"
gmsh_lib() { compgen -G "$venv/lib/libgmsh.so*" | head -1 || true; }
if [[ -z $(gmsh_lib) || ! -f $venv/include/gmshc.h ]]; then
  echo "gmsh==4.15.2 into $venv"
  python3 -m venv "$venv" || { apt_install python3-venv; python3 -m venv "$venv"; }
  "$venv/bin/pip" install -q gmsh==4.15.2
fi
gmsh_so=$(gmsh_lib)
[[ -n $gmsh_so ]] || fail "no libgmsh.so* under $venv/lib after installing the wheel"
if grep -q 'not found' <<<"$(ldd "$gmsh_so")"; then
  apt_install libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 \
    libfontconfig1 libx11-6 libgomp1
fi
echo "cc: $(cc --version | head -1); $(cmake --version | head -1); $(mpirun --version 2>&1 | head -1); gmsh: $gmsh_so"

# --- 2. install ------------------------------------------------------------------
step "scripts/install.sh $prefix"
rm -rf "$prefix"
run "$repo/scripts/install.sh" "$prefix" > "$work/install.log" || { cat "$work/install.log"; exit 1; }
tail -1 "$work/install.log"

# --- 3. build: CMake and pkg-config ------------------------------------------------
step "CMake: find_package(abgs) from $prefix"
flags="-Wall -Wextra -Werror"
rm -rf "$work/build"
run cmake -S examples_c -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" -DGMSH_ROOT="$venv" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS="$flags" > "$work/cmake.log" || { cat "$work/cmake.log"; exit 1; }
grep -q "abgs_DIR:PATH=$prefix/lib/cmake/abgs" "$work/build/CMakeCache.txt" \
  || fail "CMake did not use the installed package"
run cmake --build "$work/build" -j 2 > "$work/cmake-build.log" || { cat "$work/cmake-build.log"; exit 1; }
for b in query_basic pipeline mpi_sizing gmsh_size_callback; do
  [[ -x $work/build/$b ]] || fail "CMake did not build $b (see $work/cmake.log)"
done

step "pkg-config abgs from $prefix"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
abgs_flags=$(pkg-config --cflags --libs abgs)
abgs_rpath=-Wl,-rpath,$(pkg-config --variable=libdir abgs)
echo "pkg-config --cflags --libs abgs: $abgs_flags"
pc=$work/build-pkgconfig
rm -rf "$pc"
mkdir -p "$pc"
# shellcheck disable=SC2086 # flags are meant to be split
{
  run cc -std=c11 -O2 $flags examples_c/query_basic.c $abgs_flags $abgs_rpath -o "$pc/query_basic"
  run cc -std=c11 -O2 $flags examples_c/pipeline.c $abgs_flags $abgs_rpath -o "$pc/pipeline"
  run mpicc -std=c11 -O2 $flags examples_c/mpi_sizing.c $abgs_flags $abgs_rpath -o "$pc/mpi_sizing"
  run cc -std=c11 -O2 $flags examples_c/gmsh_size_callback.c $abgs_flags $abgs_rpath \
    -I"$venv/include" "$gmsh_so" -Wl,-rpath,"$venv/lib" -lm -o "$pc/gmsh_size_callback"
}
for b in {"$work/build","$pc"}/{query_basic,pipeline,mpi_sizing,gmsh_size_callback}; do
  # (ldd into a variable: `ldd | grep -q` fails under pipefail when grep exits early.)
  deps=$(ldd "$b")
  grep -q "$prefix/lib/libabgs.so" <<<"$deps" || fail "$b does not load $prefix/lib/libabgs.so"
done

# --- 4. run ---------------------------------------------------------------------
mpi=(mpirun -np 2 --oversubscribe)
[[ $(id -u) -ne 0 ]] || mpi+=(--allow-run-as-root)
# Containers: no cross-memory attach between ranks, loopback TCP only.
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_btl_tcp_if_include=lo \
  OMPI_MCA_oob_tcp_if_include=lo
run_all() { # run_all BUILD_DIR TAG
  local bin=$1 tag=$2 out=$work/out/$2
  rm -rf "$out"
  mkdir -p "$out"
  step "$tag: pipeline $model.stl -> coarse.abgs"
  run "$bin/pipeline" "$meshes/$model.stl" "$out/coarse.abgs" 0.02 | tee "$out/pipeline.log"
  grep -q "^wrote $out/coarse.abgs" "$out/pipeline.log" || fail "$tag: pipeline did not write coarse.abgs"
  step "$tag: query_basic coarse.abgs"
  run "$bin/query_basic" "$out/coarse.abgs" | tee "$out/query_basic.log"
  [[ $(grep -c '^[-0-9.e+]* [-0-9.e+]* [-0-9.e+]* [0-9.e+-]*$' "$out/query_basic.log") -eq 10 ]] \
    || fail "$tag: query_basic did not print 2 x 5 sizes"
  step "$tag: ${mpi[*]} mpi_sizing $model.stl"
  run "${mpi[@]}" "$bin/mpi_sizing" "$meshes/$model.stl" 200000 | tee "$out/mpi_sizing.log"
  grep -q '0 mismatches: bit-identical' "$out/mpi_sizing.log" || fail "$tag: mpi_sizing answers differ"
  step "$tag: gmsh_size_callback $model.step coarse.abgs 2"
  run "$bin/gmsh_size_callback" "$meshes/$model.step" "$out/coarse.abgs" 2 | tee "$out/gmsh.log"
  grep -q '^gmsh: [1-9][0-9]* triangles' "$out/gmsh.log" || fail "$tag: Gmsh made no triangles"
}
run_all "$work/build" cmake
run_all "$pc" pkgconfig
cmp "$work/out/cmake/coarse.abgs" "$work/out/pkgconfig/coarse.abgs" \
  || fail "the two builds' pipelines wrote different grids"
echo
echo "run_examples: every example passed ($(($(date +%s) - start)) s)"
