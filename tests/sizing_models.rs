//! The full sizing pipeline on every shared model: sizes finite, within
//! [hmin, hmax], below H0, and every face slope within the gradation bound.

mod common;

use abgs::sizing::{self, gradation::max_face_slope, SizeParams};
use abgs::Grid;

#[test]
fn sizes_on_every_shared_model_are_graded_and_bounded() {
    let dir = common::shared_meshes();
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    let mut n = 0;
    for p in names {
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !["stl", "obj", "off"].contains(&ext) {
            continue;
        }
        let g = Grid::load(&p).unwrap();
        let params = SizeParams::default();
        let f = sizing::compute(&g, &params).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let r = &f.report;
        let s = r.slope.unwrap();
        for i in 0..f.h.len() {
            assert!(
                f.h[i].is_finite() && f.h[i] > 0.0,
                "{}: h[{i}] = {}",
                p.display(),
                f.h[i]
            );
            assert!(f.h[i] <= f.h0[i], "{}: h[{i}] above H0", p.display());
            assert!(f.h0[i] >= r.hmin && f.h0[i] <= r.hmax);
        }
        let (max, over) = max_face_slope(g.vertices(), g.triangles(), &f.h, s);
        assert_eq!(
            over,
            0,
            "{}: {over} faces above the bound, max ratio {}",
            p.display(),
            max / s
        );
        assert!(r.gradation.max_slope_ratio <= 1.0 + 1e-9);
        n += 1;
    }
    assert!(n >= 10);
}
