#!/usr/bin/env bash
# GCN-ABGS against LBO-ABGS, side by side in one run: per model, one dense grid
# (`abgs grid`, defaults) and one size field (`abgs size`, defaults), then both
# simplifiers on that same sized grid (`abgs simplify --method lbo|gcn`,
# defaults), each evaluated against the dense grid (`abgs eval --json`), one
# after the other on an otherwise idle machine. Writes a markdown table with
# the acceptance checks of the GCN-ABGS issue (faces within 20 %, size
# deviation p95 <= 1.2, simplify time ratio on dense grids over 200k faces).
#
# Usage: bench/gcn_vs_lbo.sh [--big] [MODEL ...]
#   MODEL  a file name under ../shared/meshes without extension (default: every
#          STL/OBJ/OFF there; the two largest, trimesh_fm1_satellite and
#          trimesh_cycloidal, only with --big: about an hour each on 2 cores)
# Environment: ABGS_GCN_DIR (default target/gcn_vs_lbo): per model dense.vtk,
# sized.vtk, lbo.vtk, gcn.vtk, *.report.json, *.eval.json, *.time; and
# gcn_vs_lbo.md (bench/gcn_vs_lbo.py). Existing sized grids are reused.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
big=0 models=()
while (($#)); do
  case $1 in
    --big) big=1 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    -*) echo "unknown option $1" >&2; exit 2 ;;
    *) models+=("$1") ;;
  esac
  shift
done
source bench/models.sh
((${#models[@]})) || mapfile -t models < <(shared_models "$big")
out=${ABGS_GCN_DIR:-$repo/target/gcn_vs_lbo}
mkdir -p "$out"
cargo build --release -q -p abgs-cli
abgs=$repo/target/release/abgs
timed() { # timed FILE cmd...: wall seconds and peak RSS of one command
  local t=$1; shift
  /usr/bin/time -f '%e %M' -o "$t" "$@"
}
for m in "${models[@]}"; do
  f=$(model_file "$m")
  dir=$out/$m
  mkdir -p "$dir"
  echo "== $m" >&2
  if [[ ! -s $dir/sized.vtk ]]; then
    timed "$dir/grid.time" "$abgs" grid "$f" -o "$dir/dense.vtk" >"$dir/grid.log" 2>&1 ||
      { echo "   grid failed (see $dir/grid.log)" >&2; continue; }
    "$abgs" size "$dir/dense.vtk" -o "$dir/sized.vtk" >"$dir/size.log" 2>&1 ||
      { echo "   size failed (see $dir/size.log)" >&2; continue; }
  fi
  for method in lbo gcn; do
    if timed "$dir/$method.time" "$abgs" simplify "$dir/sized.vtk" -o "$dir/$method.vtk" \
      --method "$method" --report "$dir/$method.report.json" >"$dir/$method.log" 2>&1; then
      "$abgs" eval --reference "$dir/sized.vtk" --candidate "$dir/$method.vtk" --json \
        >"$dir/$method.eval.json" 2>"$dir/$method.eval.log" ||
        echo "   $method eval failed (see $dir/$method.eval.log)" >&2
      echo "   $method: $(tail -1 "$dir/$method.log")" >&2
    else
      echo "   $method failed (see $dir/$method.log)" >&2
    fi
  done
done
python3 bench/gcn_vs_lbo.py "$out" >"$out/gcn_vs_lbo.md"
echo "wrote $out/gcn_vs_lbo.md" >&2
