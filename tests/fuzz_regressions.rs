//! Inputs that the fuzz campaign (`fuzz/`, results in `fuzz/CAMPAIGN.md`) found to
//! crash, hang or over-allocate, each minimised and kept under
//! `fuzz/regressions/<target>/`. Every one must now end in a clean error.

use abgs::{Error, Grid};
use std::path::PathBuf;

/// The regression input `name` of fuzz target `target`.
fn regression(target: &str, name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/regressions")
        .join(target)
        .join(name)
}

/// Every kept input loads without a panic (a file the loader cannot take by its
/// name, e.g. the `medit` target's NUL-joined inputs, is skipped here and has a
/// test of its own below).
#[test]
fn every_regression_input_loads_or_errs_cleanly() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions");
    let mut n = 0;
    for dir in std::fs::read_dir(&root).unwrap() {
        for f in std::fs::read_dir(dir.unwrap().path()).unwrap() {
            let p = f.unwrap().path();
            if abgs::io::Format::from_path(&p).is_ok() {
                if let Err(e) = Grid::load(&p) {
                    assert!(!e.to_string().is_empty());
                }
                n += 1;
            }
        }
    }
    assert!(n > 0, "no regression inputs found under {}", root.display());
}

/// ply: coordinates near 1e275 built a grid whose squared distances overflow, so
/// no query could find a triangle, not even at a vertex of the grid. Coordinates
/// beyond `abgs::geometry::MAX_COORDINATE` (1e150) are now refused.
#[test]
fn ply_huge_coordinates_are_refused() {
    let e = Grid::load(&regression("ply", "huge_coordinates.ply")).unwrap_err();
    assert!(matches!(e, Error::NonFinite(_)), "{e}");
}

/// vtu: the same overflow through appended raw Float64 points.
#[test]
fn vtu_huge_coordinates_are_refused() {
    let e = Grid::load(&regression("vtu", "huge_coordinates.vtu")).unwrap_err();
    assert!(matches!(e, Error::NonFinite(_)), "{e}");
}

/// msh22 / msh41: a `$NodeData` announcing 1.5·10^8 (or 10^16) string tags at the
/// end of the file looped that many times on empty lines (a hang); the end of the
/// file is now a parse error.
#[test]
fn msh_nodedata_string_tag_count_is_bounded_by_the_file() {
    for target in ["msh22", "msh41"] {
        let t = std::time::Instant::now();
        let e = Grid::load(&regression(target, "nodedata_string_tag_count.msh")).unwrap_err();
        assert!(matches!(e, Error::Parse { .. }), "{e}");
        assert!(e.to_string().contains("string tags"), "{e}");
        assert!(
            t.elapsed().as_secs_f64() < 0.5,
            "{target}: {:?}",
            t.elapsed()
        );
    }
}

/// arrays_query (`fuzz/regressions/arrays_query/subnormal_sizes`, the fuzz input):
/// a grid whose sizes are all 5e-324 (the smallest subnormal) answered a size of
/// 0 at the origin, because the barycentric weights times the sizes round to 0.
/// Interpolated sizes are now kept within the corner sizes' range; the same
/// numbers through the C ABI, as the fuzz input made them.
#[test]
fn arrays_query_subnormal_sizes_interpolate_to_a_positive_size() {
    use abgs::ffi::*;
    let xyz = [
        0.0,
        0.0,
        -5.802519778458978e-50,
        -5.804607875888737e-50,
        -5.802519778458978e-50,
        -9.926157573577242e-234,
        0.0,
        -5.802519778458978e-50,
        9.0,
        -5.802519778458978e-50,
        3.882506852466698e-265,
        0.0,
    ];
    let tris = [3u32, 1, 0];
    let sizes = [5e-324; 4];
    let mut g = std::ptr::null_mut();
    // SAFETY: 4 vertices, 1 triangle, 4 sizes, a writable out-pointer.
    let st =
        unsafe { abgs_grid_from_arrays(xyz.as_ptr(), 4, tris.as_ptr(), 1, sizes.as_ptr(), &mut g) };
    assert_eq!(st, abgs_status::ABGS_OK);
    for beta in [None, Some(1.2)] {
        let mut out = f64::NAN;
        let p = [0.0; 3];
        // SAFETY: a live grid, three doubles, one writable double.
        let st = unsafe {
            match beta {
                None => abgs_query_size(g, p.as_ptr(), &mut out),
                Some(b) => abgs_query_size_volume(g, p.as_ptr(), b, &mut out),
            }
        };
        assert_eq!(st, abgs_status::ABGS_OK);
        match beta {
            // The closest point's size: the triangle's only size.
            None => assert_eq!(out, 5e-324),
            // Plus ln(1.2) times the distance (about 4e-50) to the triangle.
            Some(_) => assert!(out.is_finite() && out >= 5e-324, "{out}"),
        }
    }
    // SAFETY: a grid from abgs_grid_from_arrays, freed once.
    assert_eq!(unsafe { abgs_grid_free(g) }, abgs_status::ABGS_OK);
}

/// The other side of the same rounding: sizes near `f64::MAX` interpolated to
/// infinity at a point with weights that do not round to 1 in sum.
#[test]
fn sizes_near_f64_max_interpolate_to_a_finite_size() {
    let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let o = abgs::BuildOptions::default();
    let g = Grid::from_arrays(v, vec![[0, 1, 2]], Some(vec![f64::MAX; 3]), &o).unwrap();
    for k in 0..100 {
        let p = [0.013 * k as f64 % 0.5, 0.029 * k as f64 % 0.4, 0.1];
        assert_eq!(g.query_size(p).unwrap(), f64::MAX, "{p:?}");
        let h = g.query_volume(p, 1.5).unwrap().size;
        assert!(h.is_finite() && h > 0.0, "{h} at {p:?}");
    }
}

/// ply: a binary file whose header ends up with an element of 1.3·10^14 entries
/// and no properties (its name is defined twice, so the properties went to
/// another element) hung: skipping it read "nothing" that many times. Such an
/// element takes no bytes and is now passed over at once.
#[test]
fn ply_binary_element_without_properties_is_skipped_at_once() {
    let t = std::time::Instant::now();
    let r = Grid::load(&regression("ply", "element_without_properties.ply"));
    assert!(t.elapsed().as_secs_f64() < 0.5, "{:?}", t.elapsed());
    let e = r.unwrap_err();
    assert!(matches!(e, Error::Parse { .. }), "{e}");
}

/// deserialize (`fuzz/regressions/deserialize/huge_size_beside_small`, the fuzz
/// input: a steering byte, then a `.abgs` buffer whose length and checksum the
/// harness fixes): two cubes with one vertex size 1e197 beside sizes near 0.5.
/// The volume query's edge minimum computed `hp + t(hq − hp)`, which is 0 at
/// t = 1 when hp dwarfs hq, so a triangle scanned in one BVH (a forged but
/// valid layout: one leaf per cube) answered below every size it holds,
/// while the same grid with a built BVH pruned it. Now `(1 − t)hp + t·hq`:
/// both agree with the minimum over every triangle.
#[test]
fn deserialize_huge_size_beside_small_volume_is_exact() {
    use abgs::io::abgs_bin;
    use abgs::query::volume::triangle_min;
    let input = std::fs::read(regression("deserialize", "huge_size_beside_small")).unwrap();
    let mut b = input[1..].to_vec(); // the steering byte (even: fix length and checksum)
    let n = b.len();
    b[48..56].copy_from_slice(&(n as u64).to_le_bytes());
    let crc = crc32fast::hash(&b[..n - 4]);
    b[n - 4..].copy_from_slice(&crc.to_le_bytes());
    let g = abgs_bin::decode(&b).unwrap();
    let fresh = Grid::from_parts(g.to_parts(false)).unwrap();
    let h = g.sizes().unwrap();
    assert!(h.iter().any(|&x| x > 1e190), "the huge size is there");
    let (x, s) = ([0.808, 0.724, 0.532], 1.5f64.ln());
    let brute = g
        .triangles()
        .iter()
        .map(|t| {
            let c = t.map(|v| g.vertices()[v as usize]);
            triangle_min(x, c, t.map(|v| h[v as usize]), s).0
        })
        .fold(f64::INFINITY, f64::min);
    let (a, b) = (
        g.query_volume(x, 1.5).unwrap(),
        fresh.query_volume(x, 1.5).unwrap(),
    );
    assert_eq!(a.size, brute);
    assert_eq!(a, b);
    assert!(a.size >= 0.1, "{a:?}");
}
