//! Deterministic random point sets on and around a grid (for tests, benchmarks
//! and metrics): area-weighted surface samples, uniform box samples, and a
//! coherent walk that moves like an advancing front.

use crate::geometry::*;
use crate::mesh::Grid;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` points uniformly distributed on the surface (area-weighted triangle choice,
/// uniform barycentric coordinates), each with its triangle. O(F + n log F).
pub fn surface_points(grid: &Grid, n: usize, seed: u64) -> Vec<(u32, [f64; 3])> {
    let v = grid.vertices();
    let t = grid.triangles();
    let mut cdf = Vec::with_capacity(t.len());
    let mut acc = 0.0;
    for tri in t {
        acc += triangle_area(v[tri[0] as usize], v[tri[1] as usize], v[tri[2] as usize]);
        cdf.push(acc);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let r = rng.gen::<f64>() * acc;
            let f = cdf.partition_point(|&c| c < r).min(t.len() - 1);
            let (mut a, mut b) = (rng.gen::<f64>(), rng.gen::<f64>());
            if a + b > 1.0 {
                a = 1.0 - a;
                b = 1.0 - b;
            }
            let [p0, p1, p2] = t[f].map(|i| v[i as usize]);
            (
                f as u32,
                add(p0, add(scale(sub(p1, p0), a), scale(sub(p2, p0), b))),
            )
        })
        .collect()
}

/// `n` points near the surface: surface samples moved along their triangle's
/// normal by a uniform offset in `[-offset, offset]`.
pub fn near_surface_points(grid: &Grid, n: usize, offset: f64, seed: u64) -> Vec<[f64; 3]> {
    let v = grid.vertices();
    let t = grid.triangles();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9);
    surface_points(grid, n, seed)
        .into_iter()
        .map(|(f, p)| {
            let [a, b, c] = t[f as usize].map(|i| v[i as usize]);
            let nrm = triangle_normal2(a, b, c);
            let len = norm(nrm);
            let d = rng.gen_range(-offset..=offset);
            if len > 0.0 {
                add(p, scale(nrm, d / len))
            } else {
                p
            }
        })
        .collect()
}

/// `n` points uniform in the bounding box grown by `margin` (fraction of the
/// diagonal) on every side.
pub fn box_points(grid: &Grid, n: usize, margin: f64, seed: u64) -> Vec<[f64; 3]> {
    let b = grid.bbox();
    let m = margin * b.diagonal();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let mut p = [0.0; 3];
            for k in 0..3 {
                p[k] = rng.gen_range(b.min[k] - m..=b.max[k] + m);
            }
            p
        })
        .collect()
}

/// A coherent walk of `n` points, as an advancing front queries: each point is
/// the previous one moved by `step` in a random direction, pulled back onto the
/// surface, then lifted off it by up to `step` along a random direction. The
/// walk restarts at a random surface point every 1000 steps.
pub fn walk_points(grid: &Grid, n: usize, step: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let starts = surface_points(grid, n / 1000 + 1, seed ^ 0x5151);
    let mut out = Vec::with_capacity(n);
    let mut cur = starts[0].1;
    let mut hint = starts[0].0;
    let mut dir = [1.0, 0.0, 0.0];
    for i in 0..n {
        if i % 1000 == 0 {
            cur = starts[i / 1000].1;
            hint = starts[i / 1000].0;
        }
        let r = [
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ];
        dir = add(scale(dir, 0.8), scale(r, 0.6));
        let l = norm(dir).max(1e-300);
        dir = scale(dir, 1.0 / l);
        let moved = add(cur, scale(dir, step));
        if let Some(h) = grid.bvh().closest(moved, Some(hint)) {
            cur = h.closest.point;
            hint = h.triangle;
        }
        let j = [
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ];
        out.push(add(cur, scale(j, step)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildOptions;

    #[test]
    fn deterministic_and_on_surface() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let g = Grid::from_arrays(
            v,
            vec![[0, 1, 2], [1, 3, 2]],
            None,
            &BuildOptions::default(),
        )
        .unwrap();
        let a = surface_points(&g, 1000, 3);
        assert_eq!(a, surface_points(&g, 1000, 3));
        assert!(a.iter().all(|(_, p)| p[2] == 0.0
            && (0.0..=2.0).contains(&p[0])
            && (0.0..=1.0).contains(&p[1])));
        let w = walk_points(&g, 2500, 0.01, 1);
        assert_eq!(w.len(), 2500);
        for k in 1..w.len() {
            if k % 1000 != 0 {
                assert!(dist2(w[k], w[k - 1]) < 0.1);
            }
        }
        assert!(near_surface_points(&g, 100, 0.1, 1)
            .iter()
            .all(|p| p[2].abs() <= 0.1));
        assert_eq!(box_points(&g, 10, 0.0, 1).len(), 10);
    }
}
