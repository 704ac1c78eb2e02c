//! Volume mode against brute force on small grids: the branch-and-bound answer
//! equals the exhaustive per-triangle minimum, never exceeds the minimum over all
//! vertices and per-triangle closest points, and is not below a dense sampling
//! of every triangle by more than the sampling error.

use abgs::geometry::*;
use abgs::query::volume::triangle_min;
use abgs::{sampling, BuildOptions, Grid};

/// A UV sphere of radius 1 with sizes varying over it.
fn sphere(nu: usize, nv: usize) -> Grid {
    let mut v = vec![[0.0, 0.0, 1.0]];
    for i in 1..nv {
        let th = std::f64::consts::PI * i as f64 / nv as f64;
        for j in 0..nu {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / nu as f64;
            v.push([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
        }
    }
    v.push([0.0, 0.0, -1.0]);
    let last = (v.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * nu + j % nu) as u32;
    let mut t = Vec::new();
    for j in 0..nu {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([last, ring(nv - 1, j + 1), ring(nv - 1, j)]);
    }
    for i in 1..nv - 1 {
        for j in 0..nu {
            t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    let s = v
        .iter()
        .map(|p| 0.05 + 0.04 * (3.0 * p[0]).sin().abs() + 0.1 * (p[2] + 1.0))
        .collect();
    Grid::from_arrays(v, t, Some(s), &BuildOptions::default()).unwrap()
}

#[test]
fn volume_matches_brute_force() {
    let g = sphere(24, 12);
    let beta: f64 = 1.3;
    let s = beta.ln();
    let v = g.vertices();
    let h = g.sizes().unwrap();
    let mut pts = sampling::box_points(&g, 300, 0.5, 4);
    pts.extend(sampling::near_surface_points(&g, 300, 0.05, 5));
    for x in pts {
        let got = g.query_volume(x, beta).unwrap();
        let mut exhaustive = f64::INFINITY;
        let mut discrete = f64::INFINITY;
        let mut sampled = f64::INFINITY;
        for t in g.triangles() {
            let c = t.map(|i| v[i as usize]);
            let hh = t.map(|i| h[i as usize]);
            exhaustive = exhaustive.min(triangle_min(x, c, hh, s).0);
            for k in 0..3 {
                discrete = discrete.min(hh[k] + s * norm(sub(x, c[k])));
            }
            let cp = closest_point_triangle(x, c[0], c[1], c[2]);
            let hc = cp.bary[0] * hh[0] + cp.bary[1] * hh[1] + cp.bary[2] * hh[2];
            discrete = discrete.min(hc + s * cp.dist2.sqrt());
            let n = 12;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (b1, b2) = (i as f64 / n as f64, j as f64 / n as f64);
                    let b0 = 1.0 - b1 - b2;
                    let y = add(add(scale(c[0], b0), scale(c[1], b1)), scale(c[2], b2));
                    sampled =
                        sampled.min(b0 * hh[0] + b1 * hh[1] + b2 * hh[2] + s * norm(sub(x, y)));
                }
            }
        }
        assert_eq!(
            got.size, exhaustive,
            "branch and bound equals exhaustive search at {x:?}"
        );
        assert!(got.size <= discrete + 1e-15);
        assert!(got.size <= sampled + 1e-15);
        // Triangle edges are < 0.3 long; 1/12 of that bounds the sampling gap.
        assert!(got.size >= sampled - (s + 1.0) * 0.3 / 12.0);
        // The reported minimiser realises the value.
        let hit = g.closest(got.point, Some(got.triangle)).unwrap();
        assert!(hit.distance < 1e-12);
        assert!((hit.size + s * norm(sub(x, got.point)) - got.size).abs() < 1e-12);
    }
}

#[test]
fn volume_on_surface_is_at_most_surface_size() {
    let g = sphere(16, 8);
    for (_, p) in sampling::surface_points(&g, 500, 8) {
        let surf = g.query_size(p).unwrap();
        let vol = g.query_volume(p, 1.2).unwrap().size;
        assert!(vol <= surf + 1e-15);
    }
}
