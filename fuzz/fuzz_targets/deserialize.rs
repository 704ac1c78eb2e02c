//! Fuzzes `abgs_grid_deserialize` (the `.abgs` binary grid) on arbitrary bytes;
//! an even first byte makes the harness fix the stated length and the checksum
//! of the rest (see `abgs_fuzz::serialized`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    abgs_fuzz::serialized::run(data);
});
