//! Certified local closest-point search: the exact answer of
//! [`Bvh::closest_filtered`] for a point near a known triangle, found in the
//! star of one vertex instead of by a descent from the root.
//!
//! # The certificate
//!
//! For every vertex `v` a *reach* `r_v` is computed once: the distance from
//! `v` to the nearest triangle that does not contain `v` and carries one of
//! the labels of `v`'s star, capped at a few times the star's radius
//! ([`REACH_CAP`]), less a rounding slack.
//! For a query point `p` at distance `d_v` from `v`, every triangle `u`
//! outside `v`'s star with such a label satisfies
//!
//! ```text
//! |p − u| ≥ |v − u| − |p − v| ≥ r_v − d_v
//! ```
//!
//! so when the best triangle `B` of the wanted label in the star (distance
//! `d_B`) has `d_B + d_v < r_v`, every triangle of that label outside the
//! star is strictly farther than `B`, and `B` is the answer of the whole
//! label, ties included (ties go to the lowest index, and no tie can lie
//! outside). A search for a label the star does not hold fails at once, so
//! the reach needs to bound only the star's own labels: another body lying
//! on `v` (an assembly's contact) or the far side of a thin wall (another
//! patch) does not shrink it. The margins cover
//! rounding: the inequality is tested with a slack of a few
//! `1e-12 · max |coordinate|` (the BVH's own rounding allowance, far above
//! the error of an f64 point–triangle distance), so the answer is the BVH's
//! bit for bit: triangle, closest point and distance.
//!
//! The search starts at the corner of the start triangle nearest to `p`; when
//! the certificate fails it moves to the corner of `B` nearest to `p` and
//! tries again (a walk towards `p`, at most `MAX_STEPS` (4) stars), then gives
//! up, and the caller asks the BVH. On a well-shaped grid `r_v` is about the
//! height of the star's triangles and `d_v` at most about 0.6 of an edge for
//! a point on the surface, so it fails where `p` lies more than a fraction of
//! an edge off the surface, and at a vertex whose star holds no triangle of
//! the label.
//!
//! # Cost and ties
//!
//! Building the reaches: one filtered BVH search per vertex, O(V log F),
//! parallel; 8 bytes per vertex. A certified query evaluates one to
//! `MAX_STEPS` (4) stars of about 6 triangles (vertex stars from
//! [`crate::mesh::Topology`]), against a descent of about 30 nodes and 9
//! triangles spread over the whole tree; the star's triangles sit close
//! together in the BVH's leaf order, so its reads stay in cache.
//!
//! The search reads its stars from [`StarTables`]: each star face as its
//! BVH slot and label side by side, and each slot's corner vertices, so a
//! face costs one read of its entry and one of its corners (leaf order)
//! instead of a chain through the triangle's label, its slot and its
//! vertices, each in input order. On occt_bearing_housing's dense grid
//! (88,819 triangles) the chained search's own instructions were 26 % of
//! `perf`'s samples of `abgs simplify`, most of them on those reads; on
//! trimesh_fm1_satellite (1.46 M) the tables took the simplification from
//! 337 to 288 s. 36 bytes per triangle, built in O(F). Ties the search to the
//! mesh's vertex stars and to the BVH (corners in leaf order, the same
//! corner order as the tree's search, so distances are the same bits).

use super::bvh::{Bvh, ClosestHit};
use crate::geometry::{closest_point_triangle, dist2, ClosestPoint};
use rayon::prelude::*;

/// Most stars a search walks through before it gives up.
const MAX_STEPS: usize = 4;

/// A vertex's reach is capped at this many times its star's radius (see
/// [`StarMesh::reaches`]).
pub const REACH_CAP: f64 = 8.0;

/// One face of a vertex's star as the search reads it: its BVH slot and
/// its label.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StarFace {
    /// The face's slot in the BVH's leaf order.
    pub slot: u32,
    /// The face's label.
    pub label: u32,
}

/// The slot-ordered tables the certified search reads (module doc): the
/// stars as [`StarFace`]s (rows as the star offsets of [`StarMesh`]) and
/// each BVH slot's corner vertices, in the corner order of
/// [`Bvh::prim_corners`]. Built once per grid and labelling.
#[derive(Clone, Debug, Default)]
pub struct StarTables {
    /// Per vertex, the faces of its star (rows by the star offsets).
    pub faces: Vec<StarFace>,
    /// Per BVH slot, the vertices of its corners.
    pub slot_vertices: Vec<[u32; 3]>,
}

impl StarTables {
    /// The tables of `triangles` with stars `star_faces` (the rows of
    /// triangle indices that [`StarMesh::star_offsets`] delimits), `labels`
    /// per triangle and the BVH `bvh` over them: the same arrays the
    /// [`StarMesh`] that reads the tables holds. O(F), 36 bytes per
    /// triangle.
    pub fn build(
        triangles: &[[u32; 3]],
        star_faces: &[u32],
        labels: &[u32],
        bvh: &Bvh,
    ) -> StarTables {
        let faces = star_faces
            .iter()
            .map(|&u| StarFace {
                slot: bvh.triangle_prim[u as usize],
                label: labels[u as usize],
            })
            .collect();
        let slot_vertices = bvh
            .prim_triangle
            .iter()
            .map(|&t| triangles[t as usize])
            .collect();
        StarTables {
            faces,
            slot_vertices,
        }
    }
}

/// What the certified search reads: the vertices and triangles, the faces
/// around each vertex (compressed rows), a label per triangle, the BVH over
/// the same triangles (for its corners and rounding scale) and the
/// slot-ordered [`StarTables`] built from them.
#[derive(Clone, Copy)]
pub struct StarMesh<'a> {
    /// Vertex positions.
    pub vertices: &'a [[f64; 3]],
    /// Triangles (vertex indices).
    pub triangles: &'a [[u32; 3]],
    /// Start of each vertex's faces in `star_faces` (one more than vertices).
    pub star_offsets: &'a [u32],
    /// Faces around each vertex.
    pub star_faces: &'a [u32],
    /// Label of each triangle (a smooth patch, say); a search stays within one.
    pub labels: &'a [u32],
    /// The BVH over `triangles`.
    pub bvh: &'a Bvh,
    /// [`StarTables::build`] of the above.
    pub tables: &'a StarTables,
}

impl StarMesh<'_> {
    /// Rounding slack of distances near `p` (as the BVH's: `1e-12` of the
    /// largest coordinate magnitude).
    #[inline]
    fn slack(&self, p: &[f64; 3]) -> f64 {
        self.bvh.rounding_scale(p)
    }

    /// Faces around vertex `v`.
    #[inline(always)]
    fn star(&self, v: u32) -> &[u32] {
        let (a, b) = (
            self.star_offsets[v as usize] as usize,
            self.star_offsets[v as usize + 1] as usize,
        );
        &self.star_faces[a..b]
    }

    /// The faces around vertex `v`, as the search reads them.
    #[inline(always)]
    fn star_faces(&self, v: u32) -> &[StarFace] {
        let (a, b) = (
            self.star_offsets[v as usize] as usize,
            self.star_offsets[v as usize + 1] as usize,
        );
        &self.tables.faces[a..b]
    }

    /// The corner of the triangle in BVH slot `slot` nearest to `p` (the
    /// first in the triangle's corner order on ties) and its squared
    /// distance.
    #[inline(always)]
    fn nearest_corner(&self, slot: u32, p: &[f64; 3]) -> (u32, f64) {
        let tv = self.tables.slot_vertices[slot as usize];
        let c = &self.bvh.prim_corners[slot as usize];
        let mut best = (tv[0], dist2(*p, c[0]));
        for k in 1..3 {
            let d = dist2(*p, c[k]);
            if d < best.1 {
                best = (tv[k], d);
            }
        }
        best
    }

    /// The reach of every vertex (see the module doc): the distance to the
    /// nearest triangle not containing it whose label is one of its star's,
    /// capped at `REACH_CAP` times the star's radius (its farthest corner),
    /// less the rounding slack. A capped reach is still a lower bound; it
    /// leaves to the BVH only points several star radii off the surface
    /// (which the samples of a simplification and the queries near a grid
    /// are not), and it keeps the search local where no other triangle of
    /// the star's labels lies near (a patch that is little more than the
    /// star), which would otherwise visit the whole tree. O(V log F),
    /// parallel.
    pub fn reaches(&self) -> Vec<f64> {
        (0..self.vertices.len() as u32)
            .into_par_iter()
            .map(|v| {
                let x = self.vertices[v as usize];
                let star = self.star(v);
                let radius2 = star
                    .iter()
                    .flat_map(|&u| self.triangles[u as usize])
                    .map(|w| dist2(x, self.vertices[w as usize]))
                    .fold(0.0, f64::max);
                let cap = REACH_CAP * radius2.sqrt();
                let outside = |u: u32| {
                    let label = self.labels[u as usize];
                    !self.triangles[u as usize].contains(&v)
                        && star.iter().any(|&w| self.labels[w as usize] == label)
                };
                let reach = match self.bvh.closest_filtered_within(x, cap, outside) {
                    Some(hit) => hit.closest.dist2.sqrt(),
                    None => cap,
                };
                reach - 4.0 * self.slack(&x)
            })
            .collect()
    }

    /// The exact closest point of `p` among the triangles labelled `label`,
    /// searched from triangle `start` (which must carry `label`): `Ok` with
    /// [`Bvh::closest_filtered`]'s answer bit for bit, or `Err` with the
    /// nearest triangle of the label seen (`start` when none was) when no
    /// certificate was found within `MAX_STEPS` (4) stars: then ask the BVH,
    /// with that triangle as its hint. O(star size · steps).
    pub fn closest_near(
        &self,
        reach: &[f64],
        p: [f64; 3],
        label: u32,
        start: u32,
    ) -> Result<ClosestHit, u32> {
        if start as usize >= self.triangles.len() || self.labels[start as usize] != label {
            return Err(start);
        }
        let slack = 4.0 * self.slack(&p);
        let (mut v, mut d_v2) = self.nearest_corner(self.bvh.triangle_prim[start as usize], &p);
        let mut seed = start;
        for _ in 0..MAX_STEPS {
            let (mut tri, mut slot) = (u32::MAX, u32::MAX);
            let mut cp = ClosestPoint {
                point: p,
                bary: [1.0, 0.0, 0.0],
                dist2: f64::INFINITY,
            };
            for f in self.star_faces(v) {
                if f.label == label {
                    let c = &self.bvh.prim_corners[f.slot as usize];
                    let q = closest_point_triangle(p, c[0], c[1], c[2]);
                    // The BVH's order: nearer, then the lower index.
                    if q.dist2 < cp.dist2
                        || (q.dist2 == cp.dist2 && self.bvh.prim_triangle[f.slot as usize] < tri)
                    {
                        (tri, slot) = (self.bvh.prim_triangle[f.slot as usize], f.slot);
                        cp = q;
                    }
                }
            }
            if tri == u32::MAX {
                return Err(seed);
            }
            if cp.dist2.sqrt() + d_v2.sqrt() + slack < reach[v as usize] {
                return Ok(ClosestHit {
                    triangle: tri,
                    closest: cp,
                });
            }
            let (w, d_w2) = self.nearest_corner(slot, &p);
            if w == v {
                return Err(tri);
            }
            (v, d_v2) = (w, d_w2);
            seed = tri;
        }
        Err(seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;
    use crate::test_shapes::{rng, triangle_point, unit_square};

    /// A test surface with its labels, topology and BVH.
    struct Surface {
        v: Vec<[f64; 3]>,
        t: Vec<[u32; 3]>,
        topo: Topology,
        labels: Vec<u32>,
        bvh: Bvh,
        tables: StarTables,
    }

    impl Surface {
        fn new(v: Vec<[f64; 3]>, t: Vec<[u32; 3]>, labels: Vec<u32>) -> Surface {
            let topo = Topology::build(v.len(), &t);
            let bvh = Bvh::build(&v, &t);
            let tables = StarTables::build(&t, &topo.vertex_faces, &labels, &bvh);
            Surface {
                v,
                t,
                topo,
                labels,
                bvh,
                tables,
            }
        }

        fn mesh(&self) -> StarMesh<'_> {
            StarMesh {
                vertices: &self.v,
                triangles: &self.t,
                star_offsets: &self.topo.vertex_face_offsets,
                star_faces: &self.topo.vertex_faces,
                labels: &self.labels,
                bvh: &self.bvh,
                tables: &self.tables,
            }
        }
    }

    /// A wavy square with three labels in bands.
    fn wavy(n: usize) -> Surface {
        let (v, t) = unit_square(n, |x, y| 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let labels = t
            .iter()
            .map(|tri| {
                let x = (0..3).map(|k| v[tri[k] as usize][0]).sum::<f64>() / 3.0;
                (x * 3.0).floor().min(2.0) as u32
            })
            .collect();
        Surface::new(v, t, labels)
    }

    #[test]
    fn certified_answers_are_the_bvh_answers_bit_for_bit() {
        let s = wavy(24);
        let (t, labels, bvh, mesh) = (&s.t, &s.labels, &s.bvh, s.mesh());
        let reach = mesh.reaches();
        assert!(reach.iter().all(|r| !r.is_nan()));
        let mut seed = 7u64;
        // Near points started at their own triangle, and how many of them
        // were certified.
        let (mut certified, mut asked) = (0, 0);
        for i in 0..6000 {
            // Points on and near the surface, some exactly on vertices and
            // edges (ties between triangles), some far off.
            let tri = (rng(&mut seed) * t.len() as f64) as usize;
            let c = bvh.prim_corners[bvh.triangle_prim[tri] as usize];
            let on = triangle_point(&c, i, &mut seed);
            let off = match i % 5 {
                0 => 0.0,
                1 => 0.3,
                _ => 0.01 * (rng(&mut seed) - 0.5),
            };
            let p = [on[0], on[1], on[2] + off];
            let label = labels[tri];
            // Start at the triangle itself or a few triangles away.
            let start = if i % 3 == 0 {
                tri
            } else {
                (tri + 2 * (i % 7)) % t.len()
            };
            let want = bvh.closest_filtered(p, None, |u| labels[u as usize] == label);
            let near = off.abs() < 0.01 && start == tri;
            asked += near as usize;
            if let Ok(got) = mesh.closest_near(&reach, p, label, start as u32) {
                certified += near as usize;
                let want = want.unwrap();
                assert_eq!(got.triangle, want.triangle, "point {p:?}");
                assert_eq!(got.closest.point, want.closest.point);
                assert_eq!(got.closest.bary, want.closest.bary);
                assert_eq!(got.closest.dist2.to_bits(), want.closest.dist2.to_bits());
            }
        }
        // Most near points are certified (a star at a label's border holds
        // few triangles of the label, and the walk gives up after a few
        // stars).
        assert!(certified * 10 > asked * 8, "{certified} of {asked}");
    }

    #[test]
    fn a_start_outside_the_label_or_range_is_refused() {
        let s = wavy(6);
        let (t, labels, mesh) = (&s.t, &s.labels, s.mesh());
        let reach = mesh.reaches();
        let p = [0.9, 0.9, 0.0];
        let other = (0..t.len()).find(|&u| labels[u] != 2).unwrap() as u32;
        assert_eq!(mesh.closest_near(&reach, p, 2, other).err(), Some(other));
        assert!(mesh.closest_near(&reach, p, 2, t.len() as u32).is_err());
    }

    #[test]
    fn a_vertex_on_every_triangle_reaches_everywhere() {
        // Two triangles sharing an edge: the edge's ends lie on every
        // triangle, so any point is certified from them. The other two
        // corners reach the far triangle when it carries their label, and
        // everywhere when it does not.
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [0, 2, 3]];
        // Every reach is capped at REACH_CAP star radii (the diagonal for 0
        // and 2, a side for 1 and 3).
        let cap = |r: f64| REACH_CAP * r;
        let s = Surface::new(v.clone(), t.clone(), vec![0, 0]);
        let reach = s.mesh().reaches();
        for v in [0, 2] {
            assert!((reach[v] - cap(2f64.sqrt())).abs() < 1e-9, "{reach:?}");
        }
        for v in [1, 3] {
            assert!((reach[v] - 0.5f64.sqrt()).abs() < 1e-9, "{reach:?}");
        }
        let s = Surface::new(v, t, vec![0, 1]);
        let mesh = s.mesh();
        let reach = mesh.reaches();
        for (v, r) in reach.iter().enumerate() {
            let radius = if v % 2 == 0 { 2f64.sqrt() } else { 1.0 };
            assert!((r - cap(radius)).abs() < 1e-9, "{reach:?}");
        }
        let hit = mesh.closest_near(&reach, [0.0, 1.0, 5.0], 0, 0).unwrap();
        assert_eq!(hit.triangle, 0);
        assert_eq!(hit.closest.point, [0.5, 0.5, 0.0]);
    }

    #[test]
    fn another_label_lying_on_the_surface_leaves_the_reach_and_the_answers() {
        // Two wavy sheets 1e-7 apart, one label each (an assembly's contact):
        // the reaches ignore the other sheet, points on either are still
        // certified from their own triangle, and the answers are the BVH's.
        let (mut v, mut t) = unit_square(12, |x, y| 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let (v2, t2) = unit_square(9, |x, y| 1e-7 + 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let lone = Surface::new(v.clone(), t.clone(), vec![0; t.len()]);
        let n = v.len() as u32;
        let mut labels = vec![0; t.len()];
        v.extend(v2);
        t.extend(t2.iter().map(|f| f.map(|k| k + n)));
        labels.resize(t.len(), 1);
        let s = Surface::new(v, t, labels);
        let (t, labels, bvh, mesh) = (&s.t, &s.labels, &s.bvh, s.mesh());
        let reach = mesh.reaches();
        assert_eq!(reach[..n as usize], lone.mesh().reaches()[..]);
        let mut seed = 3u64;
        let mut certified = 0;
        for _ in 0..2000 {
            let tri = (rng(&mut seed) * t.len() as f64) as usize;
            let c = bvh.prim_corners[bvh.triangle_prim[tri] as usize];
            let (a, b) = (rng(&mut seed), rng(&mut seed));
            let (a, b) = (a.min(1.0 - b), b.min(1.0 - a));
            let p = [0, 1, 2].map(|k| c[0][k] * (1.0 - a - b) + c[1][k] * a + c[2][k] * b);
            let label = labels[tri];
            let want = bvh.closest_filtered(p, None, |u| labels[u as usize] == label);
            if let Ok(got) = mesh.closest_near(&reach, p, label, tri as u32) {
                certified += 1;
                let want = want.unwrap();
                assert_eq!(got.triangle, want.triangle);
                assert_eq!(got.closest.dist2.to_bits(), want.closest.dist2.to_bits());
            }
        }
        assert!(certified > 1800, "{certified} of 2000");
    }
}
