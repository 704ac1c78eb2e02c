//! Queries on the shared third-party models: every model loads; a linear size
//! field is reproduced exactly on the surface; off-surface answers equal the
//! field at the exact closest point found by brute force over all triangles.

mod common;

use abgs::geometry::closest_point_triangle;
use abgs::{sampling, Grid};
use rayon::prelude::*;

#[test]
fn every_model_loads_and_reports() {
    let dir = common::shared_meshes();
    let mut n = 0;
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    for p in names {
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !["stl", "obj", "off"].contains(&ext) {
            continue;
        }
        let g = Grid::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let r = g.report();
        assert!(
            r.bodies >= 1
                && g.triangles().len() + r.dropped_repeated_index + r.dropped_zero_area
                    == r.input_triangles
        );
        assert_eq!(r.boundary_edges, g.topology().boundary_edge_count());
        // Every kept triangle has a positive area and valid indices.
        assert!(g
            .triangles()
            .iter()
            .all(|t| t.iter().all(|&v| (v as usize) < g.vertices().len())));
        assert!(g.bvh().depth() <= abgs::spatial::MAX_DEPTH);
        n += 1;
    }
    assert!(n >= 10, "expected the shared models, found {n}");
}

#[test]
fn linear_field_exact_and_closest_point_brute_force() {
    let dir = common::shared_meshes();
    for name in [
        "abc_00000050.stl",
        "netgen_hinge.stl",
        "gmsh_t20_component8.stl",
    ] {
        let mut g = Grid::load(&dir.join(name)).unwrap();
        let b = g.bbox();
        let f = common::linear_field(b.min, b.diagonal());
        let sizes: Vec<f64> = g.vertices().iter().map(|&p| f(p)).collect();
        assert!(sizes.iter().all(|&s| s > 0.0));
        g.set_sizes(sizes).unwrap();
        // Where bodies touch, the tie rule (query module) reads the smallest
        // body's size at that body's own closest point, at most 2·contact
        // gap away: lower by at most |∇f| = √0.14 < 0.375 times that.
        let tie = if g.topology().body_count > 1 {
            0.375 * 2.0 * g.contact_gap()
        } else {
            0.0
        };
        let agrees = |s: f64, want: f64| s <= want + 1e-12 * want && s >= want - tie - 1e-12 * want;

        // On the surface: exact to 1e-12 relative (or lowered at a tie).
        for (_, p) in sampling::surface_points(&g, 10_000, 5) {
            let s = g.query_size(p).unwrap();
            assert!(agrees(s, f(p)), "{name}: {s} vs {}", f(p));
        }

        // Off the surface: equals the field at the brute-force closest point.
        let v = g.vertices();
        let pts = sampling::box_points(&g, 10_000, 0.1, 9);
        pts.par_iter().for_each(|&p| {
            let mut best = (f64::INFINITY, u32::MAX, [0.0; 3]);
            for (i, t) in g.triangles().iter().enumerate() {
                let cp =
                    closest_point_triangle(p, v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
                if cp.dist2 < best.0 {
                    best = (cp.dist2, i as u32, cp.point);
                }
            }
            let hit = g.bvh().closest(p, None).unwrap();
            assert_eq!(hit.closest.dist2, best.0, "{name}: distance at {p:?}");
            assert_eq!(hit.triangle, best.1, "{name}: closest triangle at {p:?}");
            let expect = f(best.2);
            let s = g.query_size(p).unwrap();
            assert!(agrees(s, expect), "{name}: {s} vs {expect} at {p:?}");
        });
    }
}
