#!/usr/bin/env bash
# Where `abgs run`'s time and memory go, stage by stage, on one or more
# models: the pipeline's stages run as separate commands with `abgs run`'s
# defaults (grid -> size -> simplify, intermediates in the binary .abgs
# format), each under `perf record` (a flat profile at 99 Hz: the functions
# taking >= 2 % of the stage's samples) when perf works here, and under
# /usr/bin/time (wall seconds, CPU seconds, peak RSS). Writes
# DIR/profile.md: per model and stage, seconds, CPU seconds, peak RSS,
# bytes per dense face, and the top functions.
#
# Usage: bench/profile.sh [--method lbo|gcn] MODEL...   (default: the two
#   largest shared models, trimesh_cycloidal trimesh_fm1_satellite)
#   MODEL  a shared model name (../shared/meshes/MODEL.stl) or a path
# Environment: ABGS_PROFILE_DIR (default target/profile), ABGS_MESHES
# (default ../shared/meshes), ABGS_BIN (an abgs binary instead of building).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
method=lbo
models=()
while (($#)); do
  case $1 in
    --method) method=$2; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) models+=("$1") ;;
  esac
  shift
done
((${#models[@]})) || models=(trimesh_cycloidal trimesh_fm1_satellite)
out=${ABGS_PROFILE_DIR:-$repo/target/profile}
meshes=${ABGS_MESHES:-../shared/meshes}
mkdir -p "$out"
source "$repo/bench/abgs_bin.sh"
perf_ok=0
if command -v perf >/dev/null && perf record -q -o "$out/.probe" -F 99 true 2>/dev/null; then
  perf_ok=1
fi
rm -f "$out/.probe"

stage() { # stage NAME STAGE COMMAND...
  local name=$1 st=$2
  shift 2
  echo "== $name: $st" >&2
  local pre=()
  ((perf_ok)) && pre=(perf record -q -F 99 -o "$out/$name.$st.perf")
  /usr/bin/time -f '%e %U %S %M' -o "$out/$name.$st.time" "${pre[@]}" "$@" \
    >"$out/$name.$st.log" 2>&1 || { echo "   failed (see $out/$name.$st.log)" >&2; return 1; }
  if ((perf_ok)); then
    perf report -i "$out/$name.$st.perf" --no-children --percent-limit 2 --stdio \
      --sort symbol 2>/dev/null | grep -E '^ +[0-9]' >"$out/$name.$st.top" || true
  fi
}

for m in "${models[@]}"; do
  input=$m
  [[ -f $input ]] || input=$meshes/$m.stl
  name=$(basename "${input%.*}")
  stage "$name" grid "$abgs" grid "$input" -o "$out/$name.dense.abgs" &&
    stage "$name" size "$abgs" size "$out/$name.dense.abgs" -o "$out/$name.sized.abgs" &&
    stage "$name" simplify "$abgs" simplify "$out/$name.sized.abgs" --method "$method" \
      -o "$out/$name.simplified.abgs" || continue
done

python3 - "$out" "$abgs" "${models[@]}" <<'EOF'
import os, subprocess, sys
out, abgs, models = sys.argv[1], sys.argv[2], sys.argv[3:]
lines = ["| model | stage | wall s | CPU s | peak RSS MB | bytes / dense face | top functions (share of the stage's samples) |",
         "|---|---|---:|---:|---:|---:|---|"]
for m in models:
    name = os.path.basename(os.path.splitext(m)[0])
    dense = os.path.join(out, f"{name}.dense.abgs")
    faces = None
    if os.path.exists(dense):
        info = subprocess.run([abgs, "info", dense], capture_output=True, text=True).stdout
        for l in info.splitlines():
            w = l.split()
            if w and w[0] == "vertices" and "triangles" in w:
                faces = int(w[w.index("triangles") + 1])
    for st in ("grid", "size", "simplify"):
        t = os.path.join(out, f"{name}.{st}.time")
        if not os.path.exists(t):
            continue
        wall, user, sys_, kb = open(t).read().split()[-4:]
        top = os.path.join(out, f"{name}.{st}.top")
        funcs = []
        if os.path.exists(top):
            for l in open(top).read().splitlines()[:6]:
                pct, sym = l.split(None, 1)
                sym = sym.split("] ", 1)[-1].strip()
                funcs.append(f"{pct} {sym[:60].rstrip()}")
        per = f"{1024 * int(kb) / faces:.0f}" if faces else "-"
        lines.append(f"| {name} | {st} | {float(wall):.1f} | {float(user) + float(sys_):.1f} | "
                     f"{int(kb) / 1024:.0f} | {per} | {'; '.join(funcs) or '-'} |")
open(os.path.join(out, "profile.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
EOF
