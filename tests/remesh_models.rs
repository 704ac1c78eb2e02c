//! The remesher on third-party models from `../shared/meshes`: the dense-grid
//! acceptance (uniform mode, defaults) on a few small ones, and the
//! size-driven mode following a computed size field. The whole table over
//! every model is `cargo run --release --example remesh_table`.

mod common;

use abgs::remesh::{quality, remesh, remesh_sized, RemeshParams};
use abgs::sizing::SizeParams;
use abgs::Grid;

fn load(name: &str) -> Grid {
    Grid::load(&common::shared_meshes().join(name)).unwrap()
}

#[test]
fn dense_grids_of_shared_models_pass_the_acceptance() {
    // One sharp-edged part, one with two bodies, one assembly of three
    // bodies with fillets.
    for name in ["netgen_hinge.stl", "occt_crankarm.stl", "abc_00000050.stl"] {
        let g = load(name);
        let out = remesh(&g, &RemeshParams::default()).unwrap();
        let a = quality::evaluate(&g, &out.grid, Some(&out.feature_edges), 30.0, 30_000);
        assert!(a.failures().is_empty(), "{name}: {:?}\n{a:?}", a.failures());
        assert_eq!(out.grid.report().dropped_zero_area, 0, "{name}");
        assert!(a.faces_out > a.faces_in, "{name}: {a:?}");
    }
}

#[test]
fn size_driven_mode_follows_a_computed_field() {
    let mut g = load("occt_crankarm.stl");
    g.compute_sizes(&SizeParams::default()).unwrap();
    let out = remesh_sized(&g, &g, &RemeshParams::default()).unwrap();
    let (mean, within) =
        quality::length_ratios(&out.grid, |p, hint| g.query_size_hinted(p, hint)).unwrap();
    assert!((0.85..=1.2).contains(&mean), "mean {mean}");
    assert!(within >= 0.9, "within {within}");
    let a = quality::evaluate(&g, &out.grid, Some(&out.feature_edges), 30.0, 20_000);
    assert!(a.min_angle_p1 >= 25.0 && a.max_angle_p99 <= 110.0, "{a:?}");
    assert_eq!((a.bodies_in, a.bodies_out), (2, 2));
    assert_eq!(a.new_boundary_edges + a.new_non_manifold_edges, 0, "{a:?}");
}
