# Sourced by the bench scripts: the shared models they run on.
# shared_models BIG: prints the names (file names under ../shared/meshes without
# extension) of every STL/OBJ/OFF model there, one per line; the two largest
# (trimesh_fm1_satellite, trimesh_cycloidal: tens of minutes each) only when
# BIG is 1.
meshes=../shared/meshes
shared_models() {
  local f m
  for f in "$meshes"/*.stl "$meshes"/*.obj "$meshes"/*.off; do
    m=$(basename "${f%.*}")
    case $m in trimesh_fm1_satellite|trimesh_cycloidal) (($1)) || continue ;; esac
    echo "$m"
  done
}
# model_file NAME: the STL/OBJ/OFF file of a shared model.
model_file() { compgen -G "$meshes/$1.*" | grep -E '\.(stl|obj|off)$' | head -1; }
