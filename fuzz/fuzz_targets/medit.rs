//! Fuzzes the Medit reader: the input is the `.mesh` text, then optionally a NUL
//! byte and the `.sol` text written beside it (no NUL: no `.sol` file).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    abgs_fuzz::load_medit(data);
});
