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
