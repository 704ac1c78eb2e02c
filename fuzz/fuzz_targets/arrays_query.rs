//! Fuzzes `abgs_grid_from_arrays` and the query, set-sizes and copy calls of the C
//! ABI on structured input (see `abgs_fuzz::arrays`).
#![no_main]

libfuzzer_sys::fuzz_target!(|input: abgs_fuzz::arrays::Input| {
    abgs_fuzz::arrays::run(&input);
});
