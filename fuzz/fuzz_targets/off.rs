//! Fuzzes the .off reader through `abgs::Grid::load` (read, weld, validate, BVH).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    abgs_fuzz::load("off", data);
});
