//! Synthetic test shapes, built as triangle soups and welded.
#![allow(dead_code)]

use abgs::{BuildOptions, Grid};

/// A soup of triangles collected face by face, welded into a grid at the end.
#[derive(Default)]
pub struct Soup {
    pub v: Vec<[f64; 3]>,
    pub t: Vec<[u32; 3]>,
}

impl Soup {
    pub fn tri(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
        let o = self.v.len() as u32;
        self.v.extend([a, b, c]);
        self.t.push([o, o + 1, o + 2]);
    }

    /// A planar quad `o + u·i/n + v·j/m` subdivided n × m, normal along u × v.
    pub fn quad(&mut self, o: [f64; 3], u: [f64; 3], v: [f64; 3], n: usize, m: usize) {
        let p = |i: usize, j: usize| {
            let (a, b) = (i as f64 / n as f64, j as f64 / m as f64);
            [
                o[0] + a * u[0] + b * v[0],
                o[1] + a * u[1] + b * v[1],
                o[2] + a * u[2] + b * v[2],
            ]
        };
        for j in 0..m {
            for i in 0..n {
                self.tri(p(i, j), p(i + 1, j), p(i + 1, j + 1));
                self.tri(p(i, j), p(i + 1, j + 1), p(i, j + 1));
            }
        }
    }

    /// An axis-aligned box surface, every edge split in `n` segments, normals
    /// outward (or inward when `inward`), optionally without its top face.
    pub fn boxed(&mut self, lo: [f64; 3], hi: [f64; 3], n: usize, inward: bool, skip_top: bool) {
        let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        type Face = ([f64; 3], [f64; 3], [f64; 3], bool);
        let faces: Vec<Face> = vec![
            (lo, [0.0, d[1], 0.0], [d[0], 0.0, 0.0], false),
            (
                [lo[0], lo[1], hi[2]],
                [d[0], 0.0, 0.0],
                [0.0, d[1], 0.0],
                skip_top,
            ),
            (lo, [d[0], 0.0, 0.0], [0.0, 0.0, d[2]], false),
            (
                [lo[0], hi[1], lo[2]],
                [0.0, 0.0, d[2]],
                [d[0], 0.0, 0.0],
                false,
            ),
            (lo, [0.0, 0.0, d[2]], [0.0, d[1], 0.0], false),
            (
                [hi[0], lo[1], lo[2]],
                [0.0, d[1], 0.0],
                [0.0, 0.0, d[2]],
                false,
            ),
        ];
        for (o, u, v, skip) in faces {
            if !skip {
                if inward {
                    self.quad(o, v, u, n, n);
                } else {
                    self.quad(o, u, v, n, n);
                }
            }
        }
    }

    pub fn grid(self) -> Grid {
        let opts = BuildOptions {
            weld_relative_tolerance: Some(1e-9),
            orient: true,
        };
        Grid::from_arrays(self.v, self.t, None, &opts).unwrap()
    }
}

/// Icosphere of radius `r` with `level` subdivisions (vertices projected on the sphere).
pub fn icosphere(r: f64, level: usize) -> Grid {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / l, p[1] / l, p[2] / l]
    };
    for p in v.iter_mut() {
        *p = unit(*p);
    }
    for _ in 0..level {
        let mut mid = std::collections::HashMap::new();
        let mut nt = Vec::new();
        for tri in &t {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
                m[k] = *mid.entry((a, b)).or_insert_with(|| {
                    let (pa, pb) = (v[a as usize], v[b as usize]);
                    v.push(unit([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                    (v.len() - 1) as u32
                });
            }
            nt.extend([
                [tri[0], m[0], m[2]],
                [tri[1], m[1], m[0]],
                [tri[2], m[2], m[1]],
                m,
            ]);
        }
        t = nt;
    }
    let v = v
        .into_iter()
        .map(|p| [p[0] * r, p[1] * r, p[2] * r])
        .collect();
    Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
}

/// Closed cylinder of radius `r`, height `h` along z, `n` segments around,
/// `m` along the height, caps as fans subdivided into `rings` rings.
pub fn cylinder(r: f64, h: f64, n: usize, m: usize, rings: usize) -> Grid {
    let mut s = Soup::default();
    let pt = |i: usize, z: f64, rr: f64| {
        let a = 2.0 * std::f64::consts::PI * (i % n) as f64 / n as f64;
        [rr * a.cos(), rr * a.sin(), z]
    };
    for j in 0..m {
        let (z0, z1) = (h * j as f64 / m as f64, h * (j + 1) as f64 / m as f64);
        for i in 0..n {
            s.tri(pt(i, z0, r), pt(i + 1, z0, r), pt(i + 1, z1, r));
            s.tri(pt(i, z0, r), pt(i + 1, z1, r), pt(i, z1, r));
        }
    }
    for (z, up) in [(0.0, false), (h, true)] {
        for k in 0..rings {
            let (r0, r1) = (
                r * k as f64 / rings as f64,
                r * (k + 1) as f64 / rings as f64,
            );
            for i in 0..n {
                let (a, b, c, d) = (
                    pt(i, z, r0),
                    pt(i + 1, z, r0),
                    pt(i + 1, z, r1),
                    pt(i, z, r1),
                );
                let mut quad = |p: [f64; 3], q: [f64; 3], w: [f64; 3]| {
                    if up {
                        s.tri(p, q, w)
                    } else {
                        s.tri(p, w, q)
                    }
                };
                if k > 0 {
                    quad(a, b, c);
                }
                quad(a, c, d);
            }
        }
    }
    s.grid()
}

/// A thick-walled tube along z as one closed body: outer radius `r_out`,
/// inner radius `r_in` (the bore), height `h`, `n` segments around and `m`
/// along the height, annular caps. Normals outward from the material.
pub fn tube(r_in: f64, r_out: f64, h: f64, n: usize, m: usize) -> Grid {
    let mut s = Soup::default();
    tube_into(&mut s, r_in, r_out, h, n, m);
    s.grid()
}

/// Adds [`tube`]'s triangles to `s`.
pub fn tube_into(s: &mut Soup, r_in: f64, r_out: f64, h: f64, n: usize, m: usize) {
    let pt = |i: usize, z: f64, rr: f64| {
        let a = 2.0 * std::f64::consts::PI * (i % n) as f64 / n as f64;
        [rr * a.cos(), rr * a.sin(), z]
    };
    for j in 0..m {
        let (z0, z1) = (h * j as f64 / m as f64, h * (j + 1) as f64 / m as f64);
        for i in 0..n {
            s.tri(pt(i, z0, r_out), pt(i + 1, z0, r_out), pt(i + 1, z1, r_out));
            s.tri(pt(i, z0, r_out), pt(i + 1, z1, r_out), pt(i, z1, r_out));
            s.tri(pt(i, z0, r_in), pt(i + 1, z1, r_in), pt(i + 1, z0, r_in));
            s.tri(pt(i, z0, r_in), pt(i, z1, r_in), pt(i + 1, z1, r_in));
        }
    }
    for i in 0..n {
        let (a, b, c, d) = (
            pt(i, h, r_in),
            pt(i + 1, h, r_in),
            pt(i + 1, h, r_out),
            pt(i, h, r_out),
        );
        s.tri(a, c, b);
        s.tri(a, d, c);
        let (a, b, c, d) = (
            pt(i, 0.0, r_in),
            pt(i + 1, 0.0, r_in),
            pt(i + 1, 0.0, r_out),
            pt(i, 0.0, r_out),
        );
        s.tri(a, b, c);
        s.tri(a, c, d);
    }
}

/// Adds the triangles of `g` to `s` (to build assemblies of several bodies).
pub fn add_grid(s: &mut Soup, g: &Grid) {
    let o = s.v.len() as u32;
    s.v.extend_from_slice(g.vertices());
    s.t.extend(g.triangles().iter().map(|t| t.map(|i| i + o)));
}

/// Torus with radii (R, r) = (3, 1), `n` × `m` quads split in two
/// (2·n·m triangles, closed, genus 1).
pub fn torus(n: usize, m: usize) -> Grid {
    let mut v = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..m {
            let w = std::f64::consts::TAU * j as f64 / m as f64;
            let rr = 3.0 + w.cos();
            v.push([rr * u.cos(), rr * u.sin(), w.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
}
