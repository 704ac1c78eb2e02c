//! The distance envelope's clearance term prevents the failure it exists for:
//! a query landing on the wrong sheet across a thin wall or a narrow gap
//! between bodies, where a size field coarser than the gap (no proximity
//! sizes, as a user's own field may be) lets chords cut across. Each shape is
//! simplified with the defaults and with the clearance term off; the first
//! must have no wrong-sheet landing, the second shows that the shape does
//! provoke them.

mod common;

use abgs::metrics::{evaluate, EvalParams};
use abgs::simplify::{simplify, SimplifyParams};
use abgs::{BuildOptions, Grid};
use common::shapes::{add_grid, cylinder, tube, tube_into, Soup};

/// `grid` with the constant size `h`.
fn sized(grid: &Grid, h: f64) -> Grid {
    Grid::from_arrays(
        grid.vertices().to_vec(),
        grid.triangles().to_vec(),
        Some(vec![h; grid.vertices().len()]),
        &BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )
    .unwrap()
}

/// Wrong-sheet share and faces of `dense` simplified with `params`.
fn wrong_sheet(dense: &Grid, params: &SimplifyParams) -> (f64, usize) {
    let s = simplify(dense, params, None).unwrap();
    let e = evaluate(
        dense,
        &s.grid,
        &EvalParams {
            samples: 20_000,
            hausdorff_samples: 1_000,
            seed: 3,
        },
    )
    .unwrap();
    (e.size_deviation.wrong_sheet, s.grid.triangles().len())
}

fn check(name: &str, dense: &Grid) {
    let on = SimplifyParams::default();
    let off = SimplifyParams {
        clearance_fraction: f64::INFINITY,
        ..on
    };
    let (w_on, f_on) = wrong_sheet(dense, &on);
    let (w_off, f_off) = wrong_sheet(dense, &off);
    eprintln!("{name}: clearance on {w_on:.2e} ({f_on} faces), off {w_off:.2e} ({f_off} faces)");
    assert!(
        w_off > 1e-2,
        "{name}: the shape does not provoke wrong sheets ({w_off})"
    );
    assert!(
        w_on <= 1e-4,
        "{name}: wrong-sheet share {w_on} with the clearance term"
    );
    assert!(
        f_on < dense.triangles().len() / 2,
        "{name}: hardly simplified"
    );
}

/// A tube whose wall (0.06) is a fifth of the size (0.3): the outer skin's
/// chords cut into the wall towards the bore.
#[test]
fn thin_wall_is_not_crossed() {
    let dense = sized(&tube(0.94, 1.0, 1.0, 120, 10), 0.3);
    assert_eq!(dense.topology().body_count, 1);
    check("thin wall", &dense);
}

/// A shaft in a bore with a gap of 0.05 and sizes of 0.3: the bore's chords
/// cut into the gap towards the shaft.
#[test]
fn shaft_in_a_bore_is_not_crossed() {
    let mut s = Soup::default();
    tube_into(&mut s, 1.05, 1.5, 1.0, 120, 10);
    add_grid(&mut s, &cylinder(1.0, 1.0, 120, 10, 3));
    let dense = sized(&s.grid(), 0.3);
    assert_eq!(dense.topology().body_count, 2);
    check("shaft in a bore", &dense);
}
