//! Input checks and repairs: hard errors (non-finite coordinates, bad indices),
//! dropped zero-area triangles, duplicate triangles, non-manifold vertices,
//! orientation made consistent per body (outward for closed bodies), and the
//! [`ValidationReport`] that names every defect found.

use super::topology::{find, union, Topology};
use crate::error::{Error, Result};
use crate::geometry::{cross, dot, norm, sub};

/// What the grid builder found and did. Every count is exact.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ValidationReport {
    /// Vertices given.
    pub input_vertices: usize,
    /// Triangles given (after fan-triangulating polygons).
    pub input_triangles: usize,
    /// Vertices merged into another by welding.
    pub welded_vertices: usize,
    /// Vertices referenced by no kept triangle (kept, so indices stay stable).
    pub unreferenced_vertices: usize,
    /// Triangles dropped because two corners are the same vertex.
    pub dropped_repeated_index: usize,
    /// Triangles dropped because their three corners are collinear (zero area).
    pub dropped_zero_area: usize,
    /// Triangles whose vertex set repeats an earlier triangle's (kept).
    pub duplicate_triangles: usize,
    /// Edges with one incident triangle (holes, open surfaces).
    pub boundary_edges: usize,
    /// Edges with more than two incident triangles.
    pub non_manifold_edges: usize,
    /// Vertices whose triangles form more than one fan (bow-ties).
    pub non_manifold_vertices: usize,
    /// Connected components through manifold edges.
    pub bodies: usize,
    /// Bodies with boundary edges.
    pub open_bodies: usize,
    /// Triangles whose orientation was reversed to agree with their neighbours
    /// (or to face outward on a closed body).
    pub flipped_triangles: usize,
    /// Bodies that cannot be oriented consistently (Möbius-like).
    pub non_orientable_bodies: usize,
    /// Triangles with a smallest angle below 1° (slivers, kept).
    pub sliver_triangles: usize,
}

impl ValidationReport {
    /// One human-readable line per defect found; empty for a clean closed manifold.
    pub fn defects(&self) -> Vec<String> {
        let mut d = Vec::new();
        let mut add = |n: usize, what: &str| {
            if n > 0 {
                d.push(format!("{n} {what}"));
            }
        };
        add(
            self.welded_vertices,
            "vertices welded (coincident within tolerance)",
        );
        add(self.unreferenced_vertices, "unreferenced vertices");
        add(
            self.dropped_repeated_index,
            "triangles dropped: repeated vertex",
        );
        add(self.dropped_zero_area, "triangles dropped: zero area");
        add(self.duplicate_triangles, "duplicate triangles");
        add(self.boundary_edges, "boundary edges");
        add(self.non_manifold_edges, "non-manifold edges");
        add(self.non_manifold_vertices, "non-manifold vertices");
        add(self.open_bodies, "open bodies");
        add(self.flipped_triangles, "triangles re-oriented");
        add(self.non_orientable_bodies, "non-orientable bodies");
        add(
            self.sliver_triangles,
            "sliver triangles (min angle < 1 deg)",
        );
        d
    }
}

/// Fails on a non-finite coordinate or an out-of-range index. O(V + F).
pub fn check_input(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<()> {
    if let Some(i) = vertices
        .iter()
        .position(|v| !crate::geometry::is_coordinate3(*v))
    {
        return Err(Error::NonFinite(format!(
            "vertex {i} has coordinates {:?} (each must be finite and within ±{:e})",
            vertices[i],
            crate::geometry::MAX_COORDINATE
        )));
    }
    let n = vertices.len();
    if let Some(f) = triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= n))
    {
        return Err(Error::OutOfRange(format!(
            "triangle {f} references vertex {:?} but there are only {n} vertices",
            triangles[f]
        )));
    }
    Ok(())
}

/// Drops triangles with a repeated corner or zero area; returns the kept ones and
/// the two drop counts. A triangle has zero area when `|ab × ac|` is within
/// rounding of 0 relative to its longest edge (4ε·max_edge²).
pub fn drop_degenerate(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
) -> (Vec<[u32; 3]>, usize, usize) {
    let mut kept = Vec::with_capacity(triangles.len());
    let (mut repeated, mut zero) = (0, 0);
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            repeated += 1;
            continue;
        }
        let [a, b, c] = t.map(|v| vertices[v as usize]);
        let (ab, ac, bc) = (sub(b, a), sub(c, a), sub(c, b));
        let l2 = dot(ab, ab).max(dot(ac, ac)).max(dot(bc, bc));
        if norm(cross(ab, ac)) <= 4.0 * f64::EPSILON * l2 {
            zero += 1;
            continue;
        }
        kept.push(*t);
    }
    (kept, repeated, zero)
}

/// Number of triangles whose vertex set equals an earlier triangle's. O(F log F).
pub fn count_duplicates(triangles: &[[u32; 3]]) -> usize {
    let mut keys: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let mut k = *t;
            k.sort_unstable();
            k
        })
        .collect();
    keys.sort_unstable();
    keys.windows(2).filter(|w| w[0] == w[1]).count()
}

/// Vertices whose incident triangles split into several fans (joined through
/// manifold edges around the vertex). O(F).
pub fn count_non_manifold_vertices(topo: &Topology, vertex_count: usize) -> usize {
    let mut count = 0;
    let mut local: Vec<u32> = Vec::new();
    for v in 0..vertex_count {
        let faces = topo.faces_of_vertex(v);
        if faces.len() < 2 {
            continue;
        }
        // Union-find over the star's faces through manifold edges containing v.
        local.clear();
        local.extend(0..faces.len() as u32);
        for (i, &f) in faces.iter().enumerate() {
            for &e in &topo.face_edges[f as usize] {
                let ed = topo.edges[e as usize];
                if ed[0] as usize != v && ed[1] as usize != v {
                    continue;
                }
                let ef = topo.faces_of_edge(e as usize);
                if ef.len() != 2 {
                    continue;
                }
                let g = if ef[0] == f { ef[1] } else { ef[0] };
                if let Ok(j) = faces.binary_search(&g) {
                    union(&mut local, i as u32, j as u32);
                }
            }
        }
        let roots = (0..faces.len() as u32)
            .filter(|&i| find(&mut local, i) == i)
            .count();
        if roots > 1 {
            count += 1;
        }
    }
    count
}

/// True when triangle `t` traverses the directed edge a→b.
#[inline]
fn has_directed(t: &[u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
}

/// Makes orientation consistent inside each body (breadth-first from its lowest
/// face, across manifold edges) and outward on closed bodies (positive signed
/// volume). Returns `(flipped_triangles, non_orientable_bodies)`. O(F).
pub fn orient(
    vertices: &[[f64; 3]],
    triangles: &mut [[u32; 3]],
    topo: &Topology,
) -> (usize, usize) {
    let nf = triangles.len();
    let mut flip = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut bad_body = vec![false; topo.body_count as usize];
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..nf {
        if seen[seed] {
            continue;
        }
        seen[seed] = true;
        queue.push_back(seed);
        while let Some(f) = queue.pop_front() {
            let t = triangles[f];
            for k in 0..3 {
                // Edge k joins corners k and k+1 of the stored triangle; f (as
                // currently oriented) traverses it a→b.
                let e = topo.face_edges[f][k] as usize;
                let ef = topo.faces_of_edge(e);
                if ef.len() != 2 {
                    continue;
                }
                let g = if ef[0] as usize == f { ef[1] } else { ef[0] } as usize;
                let (a, b) = if flip[f] {
                    (t[(k + 1) % 3], t[k])
                } else {
                    (t[k], t[(k + 1) % 3])
                };
                // Consistent neighbours traverse the shared edge the other way.
                let g_needs_flip = has_directed(&triangles[g], a, b);
                if !seen[g] {
                    seen[g] = true;
                    flip[g] = g_needs_flip;
                    queue.push_back(g);
                } else if has_directed(&oriented(&triangles[g], flip[g]), a, b) {
                    bad_body[topo.face_body[f] as usize] = true;
                }
            }
        }
    }
    // Closed, orientable bodies face outward.
    let nb = topo.body_count as usize;
    let mut open = vec![false; nb];
    for e in 0..topo.edges.len() {
        let ef = topo.faces_of_edge(e);
        if ef.len() != 2 {
            for &f in ef {
                open[topo.face_body[f as usize] as usize] = true;
            }
        }
    }
    let mut volume = vec![0.0f64; nb];
    for f in 0..nf {
        let t = oriented(&triangles[f], flip[f]);
        let [a, b, c] = t.map(|v| vertices[v as usize]);
        volume[topo.face_body[f] as usize] += dot(a, cross(b, c));
    }
    let mut flipped = 0;
    for f in 0..nf {
        let b = topo.face_body[f] as usize;
        let mut fl = flip[f];
        if !open[b] && !bad_body[b] && volume[b] < 0.0 {
            fl = !fl;
        }
        if fl {
            triangles[f].swap(1, 2);
            flipped += 1;
        }
    }
    (flipped, bad_body.iter().filter(|&&b| b).count())
}

#[inline]
fn oriented(t: &[u32; 3], flip: bool) -> [u32; 3] {
    if flip {
        [t[0], t[2], t[1]]
    } else {
        *t
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Unit cube, two outward triangles per face.
    pub(crate) fn cube() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        (v, t)
    }

    fn signed_volume(v: &[[f64; 3]], t: &[[u32; 3]]) -> f64 {
        t.iter()
            .map(|t| dot(v[t[0] as usize], cross(v[t[1] as usize], v[t[2] as usize])) / 6.0)
            .sum()
    }

    #[test]
    fn orient_fixes_flipped_faces_and_faces_outward() {
        let (v, mut t) = cube();
        assert!((signed_volume(&v, &t) - 1.0).abs() < 1e-12);
        t[3].swap(0, 1);
        t[7].swap(1, 2);
        let topo = Topology::build(8, &t);
        let (flipped, bad) = orient(&v, &mut t, &topo);
        assert_eq!((flipped, bad), (2, 0));
        assert!((signed_volume(&v, &t) - 1.0).abs() < 1e-12);
        // Inside-out cube: every face flips.
        for tri in t.iter_mut() {
            tri.swap(0, 1);
        }
        let topo = Topology::build(8, &t);
        assert_eq!(orient(&v, &mut t, &topo), (12, 0));
        assert!((signed_volume(&v, &t) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn orient_repairs_random_flips_on_a_strip() {
        // A closed tube (8 around, 6 along) with caps removed: open, orientable.
        let (n, m) = (8u32, 6u32);
        let mut v = Vec::new();
        for j in 0..=m {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                v.push([a.cos(), a.sin(), j as f64]);
            }
        }
        let id = |i: u32, j: u32| j * n + i % n;
        let mut t = Vec::new();
        for j in 0..m {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let good = t.clone();
        for (k, tri) in t.iter_mut().enumerate() {
            if (k * 7) % 3 == 0 {
                tri.swap(1, 2);
            }
        }
        let topo = Topology::build(v.len(), &t);
        let (_, bad) = orient(&v, &mut t, &topo);
        assert_eq!(bad, 0);
        // Every triangle now agrees with the original orientation (or all disagree).
        let same = t.iter().zip(&good).filter(|(a, b)| a == b).count();
        assert!(same == t.len() || same == 0, "{same} of {}", t.len());
    }

    #[test]
    fn degenerate_and_duplicate_detection() {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [0, 0, 3], [0, 1, 3], [3, 1, 0]];
        let (kept, rep, zero) = drop_degenerate(&v, &t);
        assert_eq!((kept.len(), rep, zero), (2, 1, 1));
        assert_eq!(count_duplicates(&kept), 1);
        assert!(check_input(&v, &[[0, 1, 4]]).is_err());
        assert!(check_input(&[[f64::NAN, 0.0, 0.0]], &[]).is_err());
    }

    #[test]
    fn bowtie_vertex() {
        let t = vec![[0, 1, 2], [0, 3, 4]];
        let topo = Topology::build(5, &t);
        assert_eq!(count_non_manifold_vertices(&topo, 5), 1);
    }
}
