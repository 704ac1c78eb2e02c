//! Touching bodies get one size where they touch (issue: assemblies), after
//! simplification too, and queries at a tie read the smallest body's size.
//!
//! Each assembly is built from bodies triangulated independently (as CAD
//! exporters do), given a graded, non-linear size field with its apex on the
//! contact, and simplified with `T_contact` = 1.02 (the rule asked for;
//! the default equals `T_size`, see `DEFAULT_T_CONTACT`). Simplification must not add
//! disagreement between the touching bodies' sizes: p95 and max stay within
//! 2 points of the dense grid's (whose own disagreement is the linear
//! interpolation of the field on two different triangulations). The same run
//! with the defaults shows that the shape does provoke disagreement.

mod common;

use abgs::metrics::contact::{contact_agreement, ContactAgreement};
use abgs::simplify::{simplify, SimplifyParams};
use abgs::Grid;
use common::shapes::{add_grid, cylinder, tube_into, Soup};
use common::with_sizes;

/// A cone-shaped graded field: `h0` at `apex`, growing with slope 0.15.
fn cone(apex: [f64; 3], h0: f64) -> impl Fn([f64; 3]) -> f64 {
    move |p| {
        let d =
            ((p[0] - apex[0]).powi(2) + (p[1] - apex[1]).powi(2) + (p[2] - apex[2]).powi(2)).sqrt();
        h0 + 0.15 * d
    }
}

/// Contact agreement of `grid` (a simplification of `dense`, or `dense`).
fn agreement(dense: &Grid, grid: &Grid) -> ContactAgreement {
    contact_agreement(dense, grid, 40_000, 5).unwrap()
}

/// Simplifies `dense` with `t_contact` and returns the agreement and faces.
fn simplified(dense: &Grid, t_contact: f64) -> (ContactAgreement, usize) {
    let params = SimplifyParams {
        t_contact,
        ..Default::default()
    };
    let s = simplify(dense, &params, None).unwrap();
    (agreement(dense, &s.grid), s.grid.triangles().len())
}

/// `T_contact` asked of the simplifier in these tests.
const T_CONTACT: f64 = 1.02;

/// Asserts the rule holds with [`T_CONTACT`] and matters (with the
/// defaults, it fails).
fn check(name: &str, dense: &Grid) {
    let before = agreement(dense, dense);
    assert!(before.share > 0.01, "{name}: no contact found ({before:?})");
    let (on, f_on) = simplified(dense, T_CONTACT);
    let (off, f_off) = simplified(dense, SimplifyParams::default().t_size);
    eprintln!(
        "{name}: contact share {:.3}; dense p95 {:.4} max {:.4}; rule p95 {:.4} max {:.4} ({f_on} faces); \
         relaxed p95 {:.4} max {:.4} ({f_off} faces); {} dense faces",
        before.share,
        before.p95,
        before.max,
        on.p95,
        on.max,
        off.p95,
        off.max,
        dense.triangles().len()
    );
    let (p95, max) = (before.p95 + 0.02, before.max + 0.02);
    assert!(
        off.p95 > p95 || off.max > max,
        "{name}: the shape does not provoke disagreement ({off:?})"
    );
    assert!(on.p95 <= p95, "{name}: p95 {} with the rule", on.p95);
    assert!(on.max <= max, "{name}: max {} with the rule", on.max);
    assert!(
        f_on < dense.triangles().len() / 2,
        "{name}: hardly simplified ({f_on} of {})",
        dense.triangles().len()
    );
}

/// A block on a plate: coincident planar faces triangulated differently.
#[test]
fn block_on_plate_agrees() {
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, 0.0], [2.0, 1.0, 0.2], 24, false, false);
    s.boxed([0.5, 0.25, 0.2], [1.5, 0.75, 0.7], 15, false, false);
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    check(
        "block on plate",
        &with_sizes(&g, cone([0.9, 0.5, 0.2], 0.03)),
    );
}

/// A shaft in a bore of the same radius: coincident cylinders with different
/// numbers of segments.
#[test]
fn shaft_in_bore_agrees() {
    let mut s = Soup::default();
    tube_into(&mut s, 1.0, 1.6, 1.0, 96, 12);
    add_grid(&mut s, &cylinder(1.0, 1.6, 77, 19, 6));
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    check(
        "shaft in bore",
        &with_sizes(&g, cone([1.0, 0.0, 0.5], 0.04)),
    );
}

/// A thin sheet (0.02 thick) lying on a block.
#[test]
fn sheet_on_block_agrees() {
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, 0.0], [1.0, 1.0, 0.6], 20, false, false);
    s.boxed([0.1, 0.1, 0.6], [0.9, 0.9, 0.62], 17, false, false);
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    check(
        "sheet on block",
        &with_sizes(&g, cone([0.5, 0.3, 0.6], 0.03)),
    );
}

/// Two blocks 0.01 apart (20× the contact gap of about 5e-4 of this
/// diagonal): never mixed. No contact is found, a query on one block's face
/// reads that block's own size, and simplification keeps the blocks apart.
#[test]
fn bodies_apart_are_not_mixed() {
    let mut s = Soup::default();
    s.boxed([0.0, 0.0, 0.0], [1.0, 1.0, 0.5], 12, false, false);
    s.boxed([0.0, 0.0, 0.51], [1.0, 1.0, 1.0], 9, false, false);
    let g = s.grid();
    assert_eq!(g.topology().body_count, 2);
    // Sizes 0.1 on the lower block, 0.3 on the upper.
    let dense = with_sizes(&g, |p| if p[2] > 0.505 { 0.3 } else { 0.1 });
    let a = agreement(&dense, &dense);
    assert_eq!(a.samples, 0, "{a:?}");
    for k in 0..50 {
        let x = 0.05 + 0.9 * (k as f64 * 0.618).fract();
        let y = 0.05 + 0.9 * (k as f64 * 0.414).fract();
        assert_eq!(dense.query_size([x, y, 0.5]).unwrap(), 0.1);
        assert_eq!(dense.query_size([x, y, 0.51]).unwrap(), 0.3);
        assert_eq!(dense.query_size([x, y, 0.5049]).unwrap(), 0.1);
        assert_eq!(dense.query_size([x, y, 0.5051]).unwrap(), 0.3);
    }
    let s = simplify(&dense, &SimplifyParams::default(), None).unwrap();
    assert_eq!(s.grid.topology().body_count, 2);
    assert_eq!(s.report.binding.contact, 0);
}

/// Lower block's size 0.2 + 0.1·x and upper block's 0.1 + 0.2·y: they
/// differ on the interface z = 0.5, each linear, so interpolation is exact.
const LOWER: fn([f64; 3]) -> f64 = |p| 0.2 + 0.1 * p[0];
const UPPER: fn([f64; 3]) -> f64 = |p| 0.1 + 0.2 * p[1];

/// Two unit blocks stacked at z = 0.5 with coincident faces, triangulated
/// independently (8 and 7 divisions), not welded, sized by [`LOWER`] and
/// [`UPPER`].
fn stacked_blocks() -> Grid {
    let mut a = Soup::default();
    a.boxed([0.0, 0.0, 0.0], [1.0, 1.0, 0.5], 8, false, false);
    let a = with_sizes(&a.grid(), LOWER);
    let mut b = Soup::default();
    b.boxed([0.0, 0.0, 0.5], [1.0, 1.0, 1.0], 7, false, false);
    let b = with_sizes(&b.grid(), UPPER);
    let n = a.vertices().len() as u32;
    Grid::from_arrays(
        [a.vertices(), b.vertices()].concat(),
        a.triangles()
            .iter()
            .copied()
            .chain(b.triangles().iter().map(|t| t.map(|i| i + n)))
            .collect(),
        Some([a.sizes().unwrap(), b.sizes().unwrap()].concat()),
        &abgs::BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )
    .unwrap()
}

/// The tie rule: a point on a contact reads the smaller body's size, the
/// same through plain, hinted and batch queries, and a point beside one body
/// (farther from the other than the tolerance) reads that body's own size.
#[test]
fn queries_at_a_tie_read_the_smallest_size() {
    let (lower, upper) = (LOWER, UPPER);
    let g = stacked_blocks();
    assert_eq!(g.topology().body_count, 2);
    let pts: Vec<[f64; 3]> = (0..200)
        .map(|k| {
            let x = 0.02 + 0.96 * (k as f64 * 0.618_034).fract();
            let y = 0.02 + 0.96 * (k as f64 * 0.414_214).fract();
            [x, y, 0.5]
        })
        .collect();
    let mut batch = vec![0.0; pts.len()];
    g.query_sizes(&pts, &mut batch).unwrap();
    let mut hint = u32::MAX;
    let mut lowered = 0;
    for (p, b) in pts.iter().zip(&batch) {
        let want = lower(*p).min(upper(*p));
        let got = g.query_size(*p).unwrap();
        assert!((got - want).abs() < 1e-12, "{p:?}: {got} want {want}");
        assert_eq!(g.query_size_hinted(*p, &mut hint).unwrap(), got);
        assert_eq!(*b, got);
        lowered += usize::from(lower(*p) != upper(*p));
        // Beside the lower block, 0.05 off its side: its own size.
        let beside = [1.05, p[1], 0.3];
        let own = lower([1.0, p[1], 0.3]);
        assert!((g.query_size(beside).unwrap() - own).abs() < 1e-12);
    }
    assert!(lowered > 150, "the two fields differ on the interface");
    // Volume queries are a minimum over the whole surface already.
    let v = g.query_volume([0.5, 0.5, 0.5], 1.2).unwrap().size;
    assert!(v <= lower([0.5, 0.5, 0.5]).min(upper([0.5, 0.5, 0.5])) + 1e-12);
}

/// The tie rule is keyed on the closest point: a point inside the lower
/// block, farther from the interface than the contact gap, whose closest
/// points lie on both blocks' coincident faces, reads the smaller size
/// whichever face is the nearest, and one under a part of the face that
/// touches nothing reads the lower block alone.
#[test]
fn points_under_a_contact_read_the_agreed_size_at_any_depth() {
    let (lower, upper) = (LOWER, UPPER);
    let g = stacked_blocks();
    let gap = g.contact_gap();
    let mut lowered = 0;
    for k in 0..100 {
        let x = 0.3 + 0.4 * (k as f64 * 0.618_034).fract();
        let y = 0.3 + 0.4 * (k as f64 * 0.414_214).fract();
        // 0.1 below the interface (> 100 contact gaps), nearer to it than
        // to the block's sides and bottom.
        let p = [x, y, 0.4];
        assert!(0.1 > 100.0 * gap);
        let q = [x, y, 0.5];
        let want = lower(q).min(upper(q));
        let got = g.query_size(p).unwrap();
        assert!((got - want).abs() < 1e-12, "{p:?}: {got} want {want}");
        lowered += usize::from(upper(q) < lower(q));
    }
    assert!(
        lowered > 20,
        "the upper block is smaller at {lowered} points"
    );
}
