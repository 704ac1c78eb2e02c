//! Size queries on a [`Grid`] (DESIGN §3.8).
//!
//! - **surface**: exact closest point on the grid, then barycentric interpolation
//!   of the three vertex sizes of that triangle (never a mix across triangles).
//!   Ties between equidistant triangles go to the lowest triangle index, so the
//!   answer is a function of the point alone.
//! - **ties between bodies**: where bodies of an assembly touch, a point lies
//!   on two bodies at once and the mesh there must satisfy both. So when the
//!   closest point `q` of the query (on a face of body `A`) has a face of
//!   another body within `c` = [`Grid::contact_gap`] (diagonal / 2000) of it,
//!   the answer is the smallest of those bodies' sizes, each interpolated at
//!   that body's own closest point to `q`. The rule is keyed on `q`, not on
//!   the query point: every point whose closest point lies on a contact reads
//!   the same agreed size at any distance (a point inside a plate under a
//!   block, equally near the plate's and the block's coincident faces, gets
//!   one answer whichever face rounding makes the nearest). Bodies that are
//!   apart are never mixed: another body counts only within `c` of `q`.
//!   Deterministic (a minimum), the same for plain, hinted and batch queries;
//!   on a grid of several bodies it costs one more bounded search (radius
//!   `c`) per query, and nothing on one body. Volume queries (a minimum over
//!   the whole surface) satisfy it by construction.
//! - **hinted**: the same answer, from a triangle the caller kept from a
//!   nearby query (advancing fronts query neighbours): a short walk across
//!   edges to the triangle whose prism holds the point, and a certificate
//!   that no other triangle can be as near (module
//!   [`crate::spatial::PrismMesh`]'s doc) answer most such queries with one
//!   exact point–triangle test; the others descend the BVH with their bound
//!   seeded by that triangle. A plain query uses its thread's last plain
//!   answer the same way when the point is near it (module `recent`), so
//!   callers that cannot carry a hint (a Gmsh size callback) get the walk
//!   too.
//! - **batch**: many points in parallel (rayon), each answer identical to the
//!   single query, whatever the thread count; a scattered batch is answered
//!   along a Morton curve (module `order`), for warmer caches.
//! - **volume**: `H(x) = min_y [h(y) + ln β · |x − y|]` over the surface, by branch
//!   and bound (see [`volume`]).

mod order;
mod recent;
pub mod volume;

pub(crate) use recent::new_grid_id;

use crate::error::{Error, Result};
use crate::geometry::{is_coordinate3, MAX_COORDINATE};
use crate::mesh::Grid;
use rayon::prelude::*;

pub use volume::VolumeHit;

/// Answer of a surface query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QueryHit {
    /// Triangle holding the closest point (a good hint for the next query).
    pub triangle: u32,
    /// Barycentric coordinates of the closest point on that triangle.
    pub bary: [f64; 3],
    /// The closest point.
    pub point: [f64; 3],
    /// Distance from the query point to the surface.
    pub distance: f64,
    /// Interpolated size, lowered by the tie rule between bodies where
    /// another body touches the closest point (see the module doc; NaN when
    /// the grid has no sizes).
    pub size: f64,
}

/// Most bodies one surface query reads at a contact (the closest point's
/// own and up to three more within the contact gap of it).
pub const MAX_TIED_BODIES: usize = 4;

/// Points per rayon task in batch queries; consecutive points share hints.
const BATCH_CHUNK: usize = 256;

impl Grid {
    /// Closest point and interpolated size at `p`, with an optional triangle hint
    /// (ignored when out of range). Errors only on a point that is not finite or
    /// beyond [`MAX_COORDINATE`]. A hint changes the time, never the answer:
    /// the first hinted query builds the grid's prism table (O(F log F),
    /// parallel, 16 bytes per triangle), then a point near the surface a few
    /// triangles from its hint is answered in O(1) by a certified walk
    /// ([`crate::spatial::Prisms::closest_from`]), any other by the BVH.
    /// Without a hint, the calling thread's last answer without one on this
    /// grid serves as the hint when `p` is within a few of its triangle's
    /// edges (module `recent`: queries along a front are answered by the
    /// walk without the caller carrying a hint). After three walks in a row
    /// that missed (or points out of the record's reach), the walk is set
    /// aside for 1, 2, 4, … up to 64 queries, counted per thread and grid,
    /// apart for the caller's hints and the record: points in random order
    /// pay for no walk that cannot help. Expected O(log F).
    pub fn closest(&self, p: [f64; 3], hint: Option<u32>) -> Result<QueryHit> {
        if !is_coordinate3(p) {
            return Err(non_finite_point(p));
        }
        let plain = hint.is_none();
        let hint = hint.or_else(|| recent::hint_for(self.id(), &p));
        // Whether the walk helped: it certified its answer or ended on it
        // (`None`: not walked). A walk that did not counts as a miss.
        let mut walked = None;
        let hit = match hint {
            Some(h)
                if (h as usize) < self.triangles().len()
                    && (plain || recent::may_walk_from_hint(self.id())) =>
            {
                match self.prisms().closest_from(self.bvh(), p, h) {
                    Ok(hit) => {
                        walked = Some(true);
                        Some(hit)
                    }
                    Err(seed) => {
                        let hit = self.bvh().closest_wide(p, Some(seed));
                        // A walk that ended on the answer seeded the
                        // descent with its exact bound: not a miss.
                        walked = Some(hit.is_some_and(|h| h.triangle == seed));
                        hit
                    }
                }
            }
            _ => self.bvh().closest_wide(p, hint),
        }
        .ok_or_else(|| Error::Empty("grid has no triangles".into()))?;
        if plain {
            recent::remember(self.id(), self.bvh(), hit.triangle, walked);
        } else if let Some(helped) = walked {
            recent::walked_from_hint(self.id(), helped);
        }
        let t = self.triangles()[hit.triangle as usize];
        let b = hit.closest.bary;
        let size = match self.sizes() {
            Some(s) => self.smallest_at_contact(
                hit.closest.point,
                hit.triangle,
                interpolate(t.map(|v| s[v as usize]), b),
                s,
            ),
            None => f64::NAN,
        };
        Ok(QueryHit {
            triangle: hit.triangle,
            bary: b,
            point: hit.closest.point,
            distance: hit.closest.dist2.sqrt(),
            size,
        })
    }

    /// Size at `p` (surface mode). Errors on a non-finite point (or one beyond
    /// [`MAX_COORDINATE`]) or a grid without sizes.
    pub fn query_size(&self, p: [f64; 3]) -> Result<f64> {
        self.require_sizes()?;
        Ok(self.closest(p, None)?.size)
    }

    /// Size at `p` with a hint: `*hint` is read (any value; `u32::MAX` = none) and
    /// replaced by the triangle of the answer. The size is bit-identical to
    /// [`Grid::query_size`].
    pub fn query_size_hinted(&self, p: [f64; 3], hint: &mut u32) -> Result<f64> {
        self.require_sizes()?;
        let h = self.closest(p, Some(*hint))?;
        *hint = h.triangle;
        Ok(h.size)
    }

    /// Sizes at many points, in parallel; `out[i]` answers `points[i]`.
    /// All points are checked first: on error nothing is written. A scattered
    /// batch is answered in Morton order (module `order`: the same answers, in
    /// about half the time for points in random order).
    /// O(n log F + n log n).
    pub fn query_sizes(&self, points: &[[f64; 3]], out: &mut [f64]) -> Result<()> {
        self.require_sizes()?;
        check_batch(points, out.len())?;
        // The tie rule's lists, built here in parallel rather than lazily
        // (and sequentially) by the first worker that needs them.
        if self.topology().body_count > 1 {
            self.contact_lists();
        }
        // The hinted queries' prism table, likewise.
        self.prisms();
        // Each chunk of consecutive points chains its hints.
        let run = |ps: &mut dyn Iterator<Item = &[f64; 3]>, os: &mut [f64]| -> Result<()> {
            let mut hint = u32::MAX;
            for (p, o) in ps.zip(os.iter_mut()) {
                *o = self.query_size_hinted(*p, &mut hint)?;
            }
            Ok(())
        };
        let Some(order) = order::batch_order(points) else {
            return points
                .par_chunks(BATCH_CHUNK)
                .zip(out.par_chunks_mut(BATCH_CHUNK))
                .try_for_each(|(ps, os)| run(&mut ps.iter(), os));
        };
        let mut sorted = vec![0.0; points.len()];
        order
            .par_chunks(BATCH_CHUNK)
            .zip(sorted.par_chunks_mut(BATCH_CHUNK))
            .try_for_each(|(is, os)| run(&mut is.iter().map(|&i| &points[i as usize]), os))?;
        for (&i, v) in order.iter().zip(sorted) {
            out[i as usize] = v;
        }
        Ok(())
    }

    /// The tie rule between bodies (module doc): `size`, the size at the
    /// closest point `q` on triangle `tri`, lowered to the size of every other
    /// body with a face within `contact_gap` of `q`, each at its own closest
    /// point to `q` (at most [`MAX_TIED_BODIES`] bodies in all). O(1) on one
    /// body or on a triangle no other body comes near ([`Grid::contact_faces`]),
    /// O(log F) plus O(log F) per body found otherwise.
    fn smallest_at_contact(&self, q: [f64; 3], tri: u32, size: f64, s: &[f64]) -> f64 {
        let topo = self.topology();
        if topo.body_count < 2 || !self.contact_faces()[tri as usize] {
            return size;
        }
        self.other_bodies_at(q, tri)
            .iter()
            .map(|&(t, b)| interpolate(self.triangles()[t as usize].map(|v| s[v as usize]), b))
            .fold(size, f64::min)
    }

    /// [`Grid::other_bodies_within`] for a point `q` on triangle `tri` (its
    /// closest point, say), reach [`Grid::contact_gap`], own body `tri`'s:
    /// the same answer bit for bit, read from `tri`'s contact list when it
    /// has one (see [`crate::mesh`]'s contact lists), else by the BVH. O(k)
    /// for k listed faces.
    pub(crate) fn other_bodies_at(
        &self,
        q: [f64; 3],
        tri: u32,
    ) -> arrayvec::ArrayVec<(u32, [f64; 3]), { MAX_TIED_BODIES - 1 }> {
        let body = &self.topology().face_body;
        let own = body[tri as usize];
        let gap = self.contact_gap();
        let Some(list) = self.contact_lists().get(tri) else {
            return self.other_bodies_within(q, own, gap);
        };
        let bvh = self.bvh();
        // The best face of each body within the gap, as (d², face, bary).
        let mut best: arrayvec::ArrayVec<
            (u32, f64, u32, [f64; 3]),
            { crate::mesh::MAX_CONTACT_LIST },
        > = arrayvec::ArrayVec::new();
        let r2 = gap * gap;
        // A face whose box is farther than the gap cannot be within it: the
        // box test skips most of the list. `s` bounds the rounding of both
        // distances near `q` (as the BVH's pruning allows), so no face whose
        // computed distance is within the gap is skipped.
        let s = bvh.rounding_scale(&q);
        let box_limit = (gap + s) * (gap + s) * (1.0 + 1e-12);
        // The list is sorted by a lower bound of each face's distance to
        // `tri`'s centroid: past `|q − m| + gap` (and the rounding margins)
        // no face can be within the gap (see `mesh::contact_lists`).
        let m = self.centroid(tri as usize);
        let stop =
            (crate::geometry::norm(crate::geometry::sub(q, m)) + gap + 2.0 * s) * (1.0 + 1e-9);
        for (&u, &bound) in list.faces.iter().zip(list.bounds) {
            if bound as f64 > stop {
                break;
            }
            let c = &bvh.prim_corners[bvh.triangle_prim[u as usize] as usize];
            if crate::geometry::triangle_box_distance2(c, &q) > box_limit {
                continue;
            }
            let cp = crate::geometry::closest_point_triangle(q, c[0], c[1], c[2]);
            if cp.dist2 > r2 {
                continue;
            }
            let b = body[u as usize];
            match best.iter_mut().find(|e| e.0 == b) {
                Some(e) => {
                    if cp.dist2 < e.1 || (cp.dist2 == e.1 && u < e.2) {
                        *e = (b, cp.dist2, u, cp.bary);
                    }
                }
                None => best.push((b, cp.dist2, u, cp.bary)),
            }
        }
        // Nearest body first, ties to the lower face: the BVH's order.
        best.sort_unstable_by(|x, y| x.1.total_cmp(&y.1).then(x.2.cmp(&y.2)));
        best.iter()
            .take(MAX_TIED_BODIES - 1)
            .map(|e| (e.2, e.3))
            .collect()
    }

    /// The closest point of `p` on each body other than `own` with a face
    /// within `reach` of `p`, as (triangle, barycentric coordinates): the
    /// nearest such body first, then the nearest of the rest, and so on, up
    /// to `MAX_TIED_BODIES − 1` bodies. The one search behind the tie rule,
    /// and the simplifier's agreed sizes. O(log F + k)
    /// per body found (k faces within `reach`).
    pub(crate) fn other_bodies_within(
        &self,
        p: [f64; 3],
        own: u32,
        reach: f64,
    ) -> arrayvec::ArrayVec<(u32, [f64; 3]), { MAX_TIED_BODIES - 1 }> {
        let body = &self.topology().face_body;
        let mut seen = arrayvec::ArrayVec::<u32, MAX_TIED_BODIES>::new();
        seen.push(own);
        let nodes = self.node_bodies();
        let mut found = arrayvec::ArrayVec::new();
        while !seen.is_full() {
            let Some(hit) = self.bvh().closest_filtered_within_pruned(
                p,
                reach,
                |t| !seen.contains(&body[t as usize]),
                // MIXED_LABEL is no body: mixed nodes are always searched.
                |n| !seen.contains(&nodes[n]),
            ) else {
                break;
            };
            found.push((hit.triangle, hit.closest.bary));
            seen.push(body[hit.triangle as usize]);
        }
        found
    }

    pub(crate) fn require_sizes(&self) -> Result<()> {
        if self.sizes().is_none() {
            Err(Error::NoSizes)
        } else {
            Ok(())
        }
    }
}

/// The size at barycentric coordinates `b` of a triangle with corner sizes `h`,
/// kept within `[min h, max h]`: the convex combination lies there exactly, but
/// rounding can push it out, to 0 for subnormal sizes or to infinity for sizes
/// near `f64::MAX` (both found by fuzzing), and a size must stay finite and > 0.
#[inline]
pub(crate) fn interpolate(h: [f64; 3], b: [f64; 3]) -> f64 {
    let v = b[0] * h[0] + b[1] * h[1] + b[2] * h[2];
    v.clamp(h[0].min(h[1]).min(h[2]), h[0].max(h[1]).max(h[2]))
}

/// Checks batch arguments: equal lengths and finite points.
pub(crate) fn check_batch(points: &[[f64; 3]], out_len: usize) -> Result<()> {
    if out_len != points.len() {
        return Err(Error::InvalidArgument(format!(
            "{} points but room for {out_len} results",
            points.len()
        )));
    }
    if let Some(i) = points.iter().position(|p| !is_coordinate3(*p)) {
        return Err(Error::NonFinite(format!(
            "query point {i} is {:?} (each coordinate must be finite and within ±{MAX_COORDINATE:e})",
            points[i]
        )));
    }
    Ok(())
}

/// The error for a query point that is not finite or beyond [`MAX_COORDINATE`].
pub(crate) fn non_finite_point(p: [f64; 3]) -> Error {
    Error::NonFinite(format!(
        "query point {p:?} (each coordinate must be finite and within ±{MAX_COORDINATE:e})"
    ))
}

#[cfg(test)]
mod tests {
    use crate::mesh::{BuildOptions, Grid};

    fn plate() -> Grid {
        let n = 10;
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                v.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
            }
        }
        let mut t = Vec::new();
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let s = v.iter().map(|p| 1.0 + 2.0 * p[0] + 3.0 * p[1]).collect();
        Grid::from_arrays(v, t, Some(s), &BuildOptions::default()).unwrap()
    }

    #[test]
    fn linear_field_exact_and_hint_invariant() {
        let g = plate();
        let mut hint = u32::MAX;
        for k in 0..100 {
            let x = (k as f64 * 0.0137) % 1.0;
            let y = (k as f64 * 0.0291) % 1.0;
            let s = g.query_size([x, y, 0.3]).unwrap();
            assert!((s - (1.0 + 2.0 * x + 3.0 * y)).abs() < 1e-12);
            assert_eq!(g.query_size_hinted([x, y, 0.3], &mut hint).unwrap(), s);
        }
        let far = g.query_size([5.0, 0.5, 0.0]).unwrap();
        assert!(
            (far - (1.0 + 2.0 + 1.5)).abs() < 1e-12,
            "clamped to the boundary"
        );
        assert!(g.query_size([f64::NAN, 0.0, 0.0]).is_err());
    }

    #[test]
    fn batch_equals_single() {
        let g = plate();
        // Scattered (answered in Morton order) and coherent (in their order).
        let scattered: Vec<[f64; 3]> = (0..2000)
            .map(|k| [(k as f64 * 0.37) % 1.3, (k as f64 * 0.11) % 1.1, 0.1])
            .collect();
        let coherent: Vec<[f64; 3]> = (0..2000)
            .map(|k| [k as f64 * 5e-4, 0.3 + 0.2 * (k as f64 * 0.01).sin(), 0.1])
            .collect();
        assert!(super::order::batch_order(&scattered).is_some());
        assert!(super::order::batch_order(&coherent).is_none());
        for pts in [&scattered, &coherent] {
            for threads in [1, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut out = vec![0.0; pts.len()];
                let mut vol = vec![0.0; pts.len()];
                pool.install(|| {
                    g.query_sizes(pts, &mut out).unwrap();
                    g.query_sizes_volume(pts, 1.2, &mut vol).unwrap();
                });
                for (i, p) in pts.iter().enumerate() {
                    assert_eq!(out[i].to_bits(), g.query_size(*p).unwrap().to_bits());
                    let v = g.query_volume(*p, 1.2).unwrap().size;
                    assert_eq!(vol[i].to_bits(), v.to_bits());
                }
            }
            let mut out = vec![0.0; pts.len()];
            assert!(g.query_sizes(pts, &mut out[1..]).is_err());
        }
    }

    #[test]
    fn points_beyond_max_coordinate_are_refused() {
        use crate::geometry::MAX_COORDINATE;
        use crate::Error;
        let g = plate();
        // At the limit, far from the grid: still a size of the grid (seen from
        // 1e150 away, the unit plate is a point: every triangle is at the same
        // rounded distance, and the tie goes to the lowest index).
        let s = g.query_size([MAX_COORDINATE, MAX_COORDINATE, 0.0]).unwrap();
        assert!((1.0..=6.0).contains(&s), "{s}");
        assert!(g
            .query_volume([-MAX_COORDINATE, 0.0, 0.0], 1.2)
            .unwrap()
            .size
            .is_finite());
        let beyond = [0.0, 1.000_000_000_000_000_2 * MAX_COORDINATE, 0.0];
        assert!(matches!(g.query_size(beyond), Err(Error::NonFinite(_))));
        assert!(matches!(
            g.query_volume(beyond, 1.2),
            Err(Error::NonFinite(_))
        ));
        let mut out = [0.0; 2];
        assert!(matches!(
            g.query_sizes(&[[0.0; 3], beyond], &mut out),
            Err(Error::NonFinite(_))
        ));
        assert_eq!(out, [0.0; 2], "nothing written on error");
    }
}
