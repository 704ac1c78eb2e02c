//! Fuzzes binary STL through `abgs::Grid::load`.
//!
//! An input whose first byte is even gets its facet count (bytes 80..84) set to
//! match its length and is cut to the exact binary size, so that most inputs take
//! the exact-size binary branch even after the mutator inserts or removes bytes;
//! an odd first byte leaves the input as it is (mismatched counts, truncation).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if data.len() >= 84 && data[0] % 2 == 0 {
        let n = (data.len() - 84) / 50;
        let mut bytes = data[..84 + 50 * n].to_vec();
        bytes[80..84].copy_from_slice(&(n as u32).to_le_bytes());
        abgs_fuzz::load("stl", &bytes);
    } else {
        abgs_fuzz::load("stl", data);
    }
});
