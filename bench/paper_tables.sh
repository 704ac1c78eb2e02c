#!/usr/bin/env bash
# Side-by-side harness: builds abgs, the CMake harness in cmake/harness (CGAL,
# OpenMesh, Gmsh, Netgen) and runs it on models with a STEP, then writes one
# markdown report (the paper's Tables 1-2 on our models with Gmsh and Netgen,
# plus queries, Hausdorff and decimation against CGAL and OpenMesh).
#
# Usage: bench/paper_tables.sh [--ci] [--reuse] [--only LIST] [--out FILE] [MODEL ...]
#   MODEL   a name of ../shared/meshes/MODEL.step with MODEL.stl beside it;
#           default: every model there that has a STEP
#   --ci    small and quick: coarser dense grid (--relative 0.02), fewer points
#           and samples, one timing repetition; checks agreement, not speed
#   --reuse keep the grids of an earlier run (DIR/MODEL/report.json present)
#   --only  run only these programs, comma-separated, of: queries, hausdorff,
#           decimation, gmsh, netgen, gcn (default: all); the report shows the
#           other programs' results of an earlier run where they are present
#   --out   the markdown report (default: $ABGS_HARNESS_DIR/paper_tables.md)
# Environment:
#   ABGS_HARNESS_DIR   work folder: CMake build, Gmsh venv, results
#                      (default: target/harness in the repository)
#   ABGS_HARNESS_VENV  venv holding the pinned gmsh wheel (default: DIR/venv)
# Installs what is missing when run as root: cmake, g++, libcgal-dev,
# libopenmesh-dev, libnglib-dev (Netgen 6.2's nglib; apt), gmsh==4.15.2 (pip,
# in the venv) and the X/GL libraries the Gmsh wheel links to.
# Exit status: 0 when every program ran and every agreement check passed.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
ci=0 reuse=0 out="" models=() only=queries,hausdorff,decimation,gmsh,netgen,gcn
while (($#)); do
  case $1 in
    --ci) ci=1 ;;
    --reuse) reuse=1 ;;
    --only) only=$2; shift ;;
    --out) out=$2; shift ;;
    -h|--help) sed -n '2,26p' "$0"; exit 0 ;;
    -*) echo "unknown option $1" >&2; exit 2 ;;
    *) models+=("$1") ;;
  esac
  shift
done
work=${ABGS_HARNESS_DIR:-$repo/target/harness}
venv=${ABGS_HARNESS_VENV:-$work/venv}
out=${out:-$work/paper_tables.md}
meshes=../shared/meshes
mkdir -p "$work"
work=$(cd "$work" && pwd)

step() { printf '\n== %s\n' "$*"; }
runs() { [[ ,$only, == *,$1,* ]]; }
for p in ${only//,/ }; do
  case $p in queries|hausdorff|decimation|gmsh|netgen|gcn) ;; *) echo "unknown program in --only: $p" >&2; exit 2 ;; esac
done
apt_install() {
  if [[ $(id -u) -ne 0 ]] || ! command -v apt-get >/dev/null; then
    echo "missing: $*; install them (apt-get install -y $*)" >&2
    exit 2
  fi
  echo "installing $*"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

# --- dependencies --------------------------------------------------------------
step "dependencies"
need=()
command -v cmake >/dev/null || need+=(cmake)
command -v c++ >/dev/null || need+=(g++)
command -v python3 >/dev/null || need+=(python3 python3-venv)
[[ -f /usr/include/CGAL/AABB_tree.h ]] || need+=(libcgal-dev)
[[ -f /usr/include/OpenMesh/Tools/Decimater/DecimaterT.hh ]] || need+=(libopenmesh-dev)
if runs netgen; then [[ -f /usr/include/netgen/nglib.h ]] || need+=(libnglib-dev); fi
((${#need[@]} == 0)) || apt_install "${need[@]}"
gmsh_lib() { compgen -G "$venv/lib/libgmsh.so*" | head -1 || true; }
if [[ -z $(gmsh_lib) || ! -f $venv/include/gmshc.h ]]; then
  echo "gmsh==4.15.2 into $venv"
  python3 -m venv "$venv" || { apt_install python3-venv; python3 -m venv "$venv"; }
  "$venv/bin/pip" install -q gmsh==4.15.2
fi
lib=$(gmsh_lib)
[[ -n $lib ]] || { echo "no libgmsh.so* under $venv/lib after installing the wheel" >&2; exit 2; }
if ldd "$lib" | grep -q 'not found'; then
  apt_install libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 \
    libfontconfig1 libx11-6 libgomp1
fi
echo "gmsh: $lib; CGAL $(sed -n 's/^#define CGAL_VERSION \(.*\)$/\1/p' /usr/include/CGAL/version.h)"

# --- build ---------------------------------------------------------------------
step "build: abgs library and CLI, then the harness"
# The library and the CLI in one build (features unified as in `cargo build
# --release --workspace`, so neither is rebuilt twice).
cargo build --release --workspace --lib --bin abgs
abgs=$repo/target/release/abgs
cmake -S cmake/harness -B "$work/build" -Dabgs_DIR="$repo/cmake" -DGMSH_ROOT="$venv" \
  -DCMAKE_BUILD_TYPE=Release > "$work/cmake-configure.log" || { cat "$work/cmake-configure.log"; exit 2; }
cmake --build "$work/build" -j 2
bin=$work/build

# --- models --------------------------------------------------------------------
if ((${#models[@]} == 0)); then
  for s in "$meshes"/*.step; do models+=("$(basename "$s" .step)"); done
fi
if ((ci)); then
  run_args=(--relative 0.02 --samples 20000) points=20000 reps=1 samples=20000
else
  run_args=() points=200000 reps=3 samples=100000
fi

failed=()
# run_prog NAME OUTDIR CMD...: stdout (one JSON line) to OUTDIR/NAME.json, stderr shown and kept.
run_prog() {
  local name=$1 dir=$2
  shift 2
  printf -- '-- %s\n' "$name"
  local rc=0
  "$@" > "$dir/$name.json" 2> >(tee "$dir/$name.log" >&2) || rc=$?
  if ((rc)); then
    echo "FAILED ($rc): $name" >&2
    failed+=("$(basename "$dir")/$name")
  fi
}

results=$work/results
mkdir -p "$results"
uptime > "$results/machine.txt"
nproc >> "$results/machine.txt"
for m in "${models[@]}"; do
  stl=$meshes/$m.stl step_file=$meshes/$m.step
  [[ -f $stl && -f $step_file ]] || { echo "skip $m: needs $stl and $step_file" >&2; failed+=("$m/missing"); continue; }
  dir=$results/$m
  mkdir -p "$dir"
  step "$m"
  if ((reuse)) && [[ -f $dir/report.json && -f $dir/dense.vtk && -f $dir/simplified.vtk ]]; then
    echo "reusing the grids in $dir"
  else
    "$abgs" run "$stl" -o "$dir" --no-images "${run_args[@]}" 2>&1 | tail -3
  fi
  if runs queries; then
    for g in dense simplified; do
      run_prog "queries_$g" "$dir" "$bin/compare_queries" "$dir/$g.vtk" --points "$points" --reps "$reps"
    done
  fi
  if runs hausdorff; then
    RAYON_NUM_THREADS=1 run_prog hausdorff_1t "$dir" \
      "$bin/compare_hausdorff" "$dir/dense.vtk" "$dir/simplified.vtk" --samples "$samples"
    run_prog hausdorff_mt "$dir" "$bin/compare_hausdorff" "$dir/dense.vtk" "$dir/simplified.vtk" --samples "$samples"
  fi
  if runs decimation; then
    run_prog decimation "$dir" "$bin/compare_decimation" "$dir/dense.vtk" "$dir/simplified.vtk" --samples "$samples"
  fi
  if runs gmsh; then
    run_prog gmsh "$dir" "$bin/gmsh_mesh" "$step_file" --dense "$dir/dense.vtk" \
      --simplified "$dir/simplified.vtk" --stl "$stl" --samples "$samples"
  fi
  # Netgen (nglib) on the same STEP with the same three grids as restriction
  # points; the agreement check (simplified against dense) sets its exit status.
  if runs netgen; then
    run_prog netgen "$dir" "$bin/netgen_mesh" "$step_file" --dense "$dir/dense.vtk" \
      --simplified "$dir/simplified.vtk" --stl "$stl" --check
  fi
  # GCN-ABGS (the embedded model) on the same dense grid, defaults, and the
  # same Gmsh program on its grid (dense and STL rows repeat as anchors).
  if runs gcn; then
    printf -- '-- gcn\n'
    "$abgs" simplify "$dir/dense.vtk" --method gcn -o "$dir/gcn.vtk" --report "$dir/gcn_report.json" 2>&1 | tail -1 \
      || { echo "FAILED: gcn" >&2; failed+=("$m/gcn"); }
    run_prog gmsh_gcn "$dir" "$bin/gmsh_mesh" "$step_file" --dense "$dir/dense.vtk" \
      --simplified "$dir/gcn.vtk" --stl "$stl" --samples "$samples"
  fi
done

step "report"
mode=full
((ci)) && mode=ci
python3 bench/paper_tables.py --mode "$mode" "$results" "${models[@]}" > "$out"
echo "wrote $out"
if ((${#failed[@]})); then
  echo "failed: ${failed[*]}" >&2
  exit 1
fi
echo "all programs ran; every agreement check passed"
