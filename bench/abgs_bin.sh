# Sourced by the bench scripts: sets `abgs` to the binary to measure, ABGS_BIN
# when set, else a fresh release build of this checkout. Needs `repo`.
if [[ -n ${ABGS_BIN:-} ]]; then
  abgs=$ABGS_BIN
else
  cargo build --release -q -p abgs-cli
  abgs=$repo/target/release/abgs
fi
