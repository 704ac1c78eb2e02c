//! The `deserialize` target: `abgs_grid_deserialize` (the C ABI over
//! `abgs::io::abgs_bin::decode`) on arbitrary bytes.
//!
//! The first input byte steers: even, the rest of the input gets its stated
//! length (bytes 48..56) and its CRC-32 (the last 4 bytes) made right, so that
//! mutations reach the counts, the sections and the content behind the
//! checksum; odd, the rest goes in as it is (framing, truncation, checksum).
//!
//! A call must return a status other than `ABGS_ERR_INTERNAL` (a panic aborts
//! the fuzzer first). A grid that loads must satisfy [`crate::check_grid`],
//! serialise back to exactly the bytes it came from, and answer the closest
//! point at a few points exactly (bit for bit), and the volume size to
//! rounding, as a grid built from the same arrays with a new BVH: a forged
//! BVH layout can change nothing. (The volume query's per-triangle minimum
//! is exact only to rounding, and two trees scan different triangles.)

use abgs::ffi::*;
use abgs::io::abgs_bin;
use abgs::Grid;
use std::ptr::null_mut;

/// Runs one input.
pub fn run(data: &[u8]) {
    crate::setup();
    let Some((&ctl, rest)) = data.split_first() else {
        return;
    };
    let mut bytes = rest.to_vec();
    if ctl % 2 == 0 && bytes.len() >= abgs_bin::MIN_LEN {
        let n = bytes.len();
        bytes[48..56].copy_from_slice(&(n as u64).to_le_bytes());
        let crc = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    }
    let mut out: *mut abgs_grid = null_mut();
    // SAFETY: `bytes` holds `len` readable bytes; `out` is writable.
    let st = unsafe { abgs_grid_deserialize(bytes.as_ptr().cast(), bytes.len(), &mut out) };
    if st != abgs_status::ABGS_OK {
        assert_ne!(st, abgs_status::ABGS_ERR_INTERNAL, "internal error");
        assert!(out.is_null(), "out_grid set on failure");
        if crate::verbose() {
            eprintln!("{st:?}: {}", last_message());
        }
        return;
    }
    assert!(!out.is_null());
    // SAFETY: a grid from this library, freed once below.
    unsafe { abgs_grid_free(out) };
    // The same bytes through the Rust API, to look inside.
    let g = abgs_bin::decode(&bytes).expect("the C call accepted these bytes");
    if crate::verbose() {
        eprintln!(
            "loaded: {} vertices, {} triangles, {} BVH nodes",
            g.vertices().len(),
            g.triangles().len(),
            g.bvh().nodes.len()
        );
    }
    crate::check_grid(&g);
    assert_eq!(abgs_bin::encode_with(&g, bytes[16] & 2 != 0), bytes, "not a fixed point");
    let fresh = Grid::from_parts(g.to_parts(false)).expect("the same arrays build a grid");
    let b = g.bbox();
    let mut points = vec![g.vertices()[g.triangles()[0][1] as usize]];
    for k in 0..6u32 {
        let t = [0.1 + 0.17 * k as f64, 0.9 - 0.13 * k as f64, 0.3 + 0.11 * k as f64];
        points.push([0, 1, 2].map(|i| {
            let (lo, hi) = (b.min[i], b.max[i]);
            lo + (t[i] * 1.6 - 0.3) * (hi - lo)
        }));
    }
    for p in points {
        // Debug text: the same bits, NaN (no sizes) equal to NaN.
        let (a, b) = (g.closest(p, None).ok(), fresh.closest(p, None).ok());
        assert_eq!(format!("{a:?}"), format!("{b:?}"), "at {p:?}");
        if let (Some(_), Ok(a), Ok(b)) = (
            g.sizes(),
            g.query_volume(p, 1.5),
            fresh.query_volume(p, 1.5),
        ) {
            // Both trees prune with the same exact bounds, but each triangle's
            // minimum is computed with rounding (a point within rounding of a
            // triangle counts as on it), so the trees, which scan different
            // triangles, agree to rounding, not to the bit.
            let s = 1.5f64.ln();
            let scale = g.bvh().coord_scale + p.iter().fold(0.0f64, |m, c| m.max(c.abs()));
            let tol = 1e-9 * a.size.max(b.size) + s * 1e-6 * scale;
            assert!(
                a.size.is_finite() && a.size > 0.0 && (a.size - b.size).abs() <= tol,
                "volume at {p:?}: {a:?} with the stored layout, {b:?} with a built BVH"
            );
        }
    }
}

fn last_message() -> String {
    // SAFETY: the library returns a valid NUL-terminated thread-local string.
    unsafe { std::ffi::CStr::from_ptr(abgs_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}
