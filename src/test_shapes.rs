//! Synthetic shapes and pseudo-random numbers shared by the unit tests.

/// Deterministic pseudo-random numbers in [0, 1) (a 64-bit LCG).
pub(crate) fn rng(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// A point of triangle `c` for the `i`-th test point: its first corner when
/// `i % 4 == 0`, the midpoint of its second edge when 1 (both ties between
/// triangles), else a random point inside. Draws two numbers either way.
pub(crate) fn triangle_point(c: &[[f64; 3]; 3], i: usize, seed: &mut u64) -> [f64; 3] {
    let (a, b) = (rng(seed), rng(seed));
    let (a, b) = match i % 4 {
        0 => (1.0, 0.0),
        1 => (0.5, 0.5),
        _ => (a.min(1.0 - b), b.min(1.0 - a)),
    };
    [0, 1, 2].map(|k| c[0][k] * (1.0 - a - b) + c[1][k] * a + c[2][k] * b)
}

/// The unit square subdivided `n × n` (two triangles per cell, counter-
/// clockwise seen from +z), lifted to `z(x, y)`: `(n+1)²` vertices row by
/// row, `2n²` triangles.
pub(crate) fn unit_square(n: usize, z: impl Fn(f64, f64) -> f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            v.push([x, y, z(x, y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, t)
}

/// The unit cube as 6 outward faces, each an `n`×`n` grid of squares split
/// into two triangles (6 smooth patches, 12 crease lines).
pub(crate) fn box_grid(n: usize) -> crate::mesh::Grid {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let mut face = |o: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        let base = v.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (s, r) = (i as f64 / n as f64, j as f64 / n as f64);
                v.push([0, 1, 2].map(|k| o[k] + s * a[k] + r * b[k]));
            }
        }
        let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    };
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    face([0.0; 3], y, x);
    face([0.0, 0.0, 1.0], x, y);
    face([0.0; 3], x, z);
    face([0.0, 1.0, 0.0], z, x);
    face([0.0; 3], z, y);
    face([1.0, 0.0, 0.0], y, z);
    let opts = crate::mesh::BuildOptions {
        weld_relative_tolerance: Some(1e-9),
        orient: false,
    };
    crate::mesh::Grid::from_arrays(v, t, None, &opts).expect("valid box")
}

/// Three fins on one edge: triangles on the segment from `(0, 0, 0)` to
/// `(len, 0, 0)` (vertices 0 and 1), their apexes at `len / 2` along it
/// and `len` off it in three directions (+y, −y, +z): a non-manifold edge,
/// three bodies once split.
pub(crate) fn three_fins(len: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let h = 0.5 * len;
    (
        vec![
            [0.0, 0.0, 0.0],
            [len, 0.0, 0.0],
            [h, len, 0.0],
            [h, -len, 0.0],
            [h, 0.0, len],
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    )
}

/// Four open sheets: three meet along the line `y = z = 0`, `0 ≤ x ≤ 1` (a
/// non-manifold edge line: the first is bent, `z = 0.1·x·y`, the second
/// stands on the line, the third continues the first into `y < 0`), the
/// fourth, bent `z = 0.2·x`, lies apart at `x ≥ 3`. Welded, not reoriented.
pub(crate) fn touching_sheets() -> crate::mesh::Grid {
    let (mut v, mut t) = unit_square(4, |x, y| 0.1 * x * y);
    let mut add = |(sv, st): (Vec<[f64; 3]>, Vec<[u32; 3]>), f: &dyn Fn([f64; 3]) -> [f64; 3]| {
        let o = v.len() as u32;
        v.extend(sv.into_iter().map(f));
        t.extend(st.into_iter().map(|x| x.map(|i| i + o)));
    };
    add(unit_square(4, |_, _| 0.0), &|p| [p[0], 0.0, p[1]]);
    add(unit_square(4, |_, _| 0.0), &|p| [p[0], -p[1], 0.0]);
    add(unit_square(3, |x, _| 0.2 * x), &|p| {
        [p[0] + 3.0, p[1], p[2]]
    });
    let opts = crate::mesh::BuildOptions {
        weld_relative_tolerance: Some(1e-9),
        orient: false,
    };
    crate::mesh::Grid::from_arrays(v, t, None, &opts).expect("valid sheets")
}

/// The triangles of `(vertices, triangles)` as corner coordinates' bits,
/// each rotated to start at its least corner, sorted: equal for two meshes
/// exactly when they have the same triangles, whatever their order.
pub(crate) fn canonical_triangles(v: &[[f64; 3]], t: &[[u32; 3]]) -> Vec<[[u64; 3]; 3]> {
    let mut s: Vec<[[u64; 3]; 3]> = t
        .iter()
        .map(|f| {
            let mut c = f.map(|i| v[i as usize].map(f64::to_bits));
            let k = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
            c.rotate_left(k);
            c
        })
        .collect();
    s.sort_unstable();
    s
}

/// `n` random small triangles (sides up to 0.05) in the unit cube, three
/// vertices of their own each (a soup: no shared vertices).
pub(crate) fn triangle_soup(n: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut v = Vec::new();
    let mut t = Vec::new();
    for i in 0..n {
        let c = [rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()];
        for _ in 0..3 {
            v.push([
                c[0] + 0.05 * rng.gen::<f64>(),
                c[1] + 0.05 * rng.gen::<f64>(),
                c[2] + 0.05 * rng.gen::<f64>(),
            ]);
        }
        t.push([3 * i as u32, 3 * i as u32 + 1, 3 * i as u32 + 2]);
    }
    (v, t)
}
