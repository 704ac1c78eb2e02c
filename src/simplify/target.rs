//! The target grid a simplification must stay faithful to: the dense grid with
//! its smoothed sizes, its smooth patches and its feature lines. Every
//! projection is exact (closest point through a BVH) and restricted to the
//! patch or line the projected point belongs to, so a thin wall or a narrow
//! gap never mixes sizes or geometry of its two sides.
//!
//! **Contacts.** Where bodies touch (coincident faces of an assembly, a shaft
//! in a bore), a point of one body lies on another too, and the mesher reads
//! whichever body its search meets first: the two must agree. So the target's
//! size at a point is the *agreed* one, the smallest of the bodies there (the
//! queries' tie rule): a projection onto body `A` that lands within the
//! contact gap of another body's face takes the smaller of the two sizes and
//! says so ([`Hit::contact`]), and the estimates hold such points to the
//! contact tolerance `T_contact` instead of `T_size` (see
//! [`super::estimate::Limits::t_contact`]). Both bodies then follow one field
//! closely wherever they touch, whatever their triangles, and so agree with
//! each other. Which target triangles come near another body is found once
//! ([`Grid::contact_faces`], conservative), so the extra search is paid only
//! there, and it reads a short list of the other bodies' faces near each such
//! triangle instead of searching the BVH from its root ([`Grid::other_bodies_at`]).

use super::envelope::Envelope;
use super::estimate::Limits;
use crate::geometry::{cross, lerp, sub};
use crate::mesh::feature_lines::FeatureLines;
use crate::mesh::shape::unit;
use crate::mesh::Grid;
use crate::spatial::{LabelForest, StarMesh, StarTables};

/// Where a point lands on the target.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// The closest point.
    pub point: [f64; 3],
    /// The target triangle (patch projection) or feature segment (line
    /// projection) found: the next hint.
    pub index: u32,
    /// Distance from the query point.
    pub dist: f64,
    /// Target size at the closest point (barycentric interpolation), the
    /// smaller of the bodies' at a contact.
    pub size: f64,
    /// The point lies on another body too (within the contact gap).
    pub contact: bool,
}

/// The target grid with its patches and feature lines.
pub struct Target<'a> {
    /// The dense grid (with sizes).
    pub grid: &'a Grid,
    /// Its sizes.
    pub sizes: &'a [f64],
    /// Smooth patch of each target triangle.
    pub face_patch: &'a [u32],
    /// Feature lines of the target (segments are target edges).
    pub lines: &'a FeatureLines,
    /// Target sizes at the two ends of each line segment.
    pub seg_sizes: &'a [[f64; 2]],
    /// Gradient and clearance per target triangle.
    pub envelope: &'a Envelope,
    /// Per target triangle: another body's face may lie within the contact
    /// gap of it (empty for a single body; see [`Grid::contact_faces`]).
    pub contact: &'a [bool],
    /// Per target vertex: its reach (the distance to the nearest triangle
    /// not containing it), for searches that start from a known triangle
    /// ([`StarMesh::reaches`]).
    pub reach: &'a [f64],
    /// The star search's slot-ordered stars ([`StarTables`]).
    pub stars: &'a StarTables,
    /// A BVH per patch, for the projections the star search cannot
    /// certify (see [`LabelForest`]).
    pub patches: &'a LabelForest,
}

impl<'a> Target<'a> {
    /// The target grid's triangles, vertex stars and patches, as the
    /// certified star search reads them.
    pub fn star_mesh(grid: &'a Grid, face_patch: &'a [u32], stars: &'a StarTables) -> StarMesh<'a> {
        let topo = grid.topology();
        StarMesh {
            vertices: grid.vertices(),
            triangles: grid.triangles(),
            star_offsets: &topo.vertex_face_offsets,
            star_faces: &topo.vertex_faces,
            labels: face_patch,
            bvh: grid.bvh(),
            tables: stars,
        }
    }

    /// How far the simplified grid may lie from the target at target triangle
    /// `tri` (`NONE`: unknown, the size term with no gradient and no
    /// clearance), the target size being `h` there and `h_loc` at the edge
    /// (see [`super::envelope`]). O(1).
    #[inline]
    pub fn allowance(&self, tri: u32, h: f64, h_loc: f64, lim: &Limits) -> f64 {
        let (g, c) = match self.envelope.gradient.get(tri as usize) {
            Some(&g) => (g, self.envelope.clearance[tri as usize]),
            None => (0.0, f64::INFINITY),
        };
        lim.size_term.allowance(h, h_loc, g).min(lim.kappa * c)
    }

    /// Unit normal of target triangle `tri` (`None` when it is degenerate or
    /// out of range). O(1).
    #[inline]
    pub fn unit_normal(&self, tri: u32) -> Option<[f64; 3]> {
        let t = self.grid.triangles().get(tri as usize)?;
        let v = self.grid.vertices();
        let [a, b, c] = t.map(|i| v[i as usize]);
        unit(cross(sub(b, a), sub(c, a)))
    }

    /// Closest point of `p` on patch `patch` (anywhere on the target when the
    /// patch is empty), starting from triangle `hint`: in the star of the
    /// hint's corner nearest `p` when its certificate holds, else by the
    /// patch's own BVH (the same answer either way, see [`StarMesh`] and
    /// [`LabelForest`]). O(1) near the hint, O(log F) typically.
    pub fn on_patch(&self, p: [f64; 3], patch: u32, hint: u32) -> Option<Hit> {
        let bvh = self.grid.bvh();
        let near = Target::star_mesh(self.grid, self.face_patch, self.stars)
            .closest_near(self.reach, p, patch, hint);
        let hit = match near {
            Ok(hit) => hit,
            Err(seed) => {
                let hint = (seed != u32::MAX).then_some(seed);
                self.patches
                    .closest(bvh, p, patch, hint)
                    .or_else(|| bvh.closest(p, None))?
            }
        };
        let t = self.grid.triangles()[hit.triangle as usize];
        let b = hit.closest.bary;
        let size = b[0] * self.sizes[t[0] as usize]
            + b[1] * self.sizes[t[1] as usize]
            + b[2] * self.sizes[t[2] as usize];
        let (size, contact) = if self.contact.get(hit.triangle as usize) == Some(&true) {
            self.agreed(hit.closest.point, hit.triangle, size)
        } else {
            (size, false)
        };
        Some(Hit {
            point: hit.closest.point,
            index: hit.triangle,
            dist: hit.closest.dist2.sqrt(),
            size,
            contact,
        })
    }

    /// The agreed size at point `q` of target triangle `tri` (size `size`
    /// there): the smallest of the sizes of the bodies with a face within the
    /// contact gap of `q`, each at its own closest point, and whether any
    /// other body was found. O(k) from `tri`'s contact list of k faces
    /// ([`Grid::other_bodies_at`]), O(log F) per body where it has none.
    fn agreed(&self, q: [f64; 3], tri: u32, size: f64) -> (f64, bool) {
        let others = self.grid.other_bodies_at(q, tri);
        let best = others
            .iter()
            .map(|&(t, b)| {
                let t = self.grid.triangles()[t as usize];
                b[0] * self.sizes[t[0] as usize]
                    + b[1] * self.sizes[t[1] as usize]
                    + b[2] * self.sizes[t[2] as usize]
            })
            .fold(size, f64::min);
        (best, !others.is_empty())
    }

    /// Closest point of `p` on feature line `line`. O(log S) typically.
    pub fn on_line(&self, p: [f64; 3], line: u32, hint: u32) -> Option<Hit> {
        let hint = if hint == u32::MAX { 0 } else { hint };
        let hit = self.lines.closest(p, line, hint)?;
        let s = self.seg_sizes[hit.triangle as usize];
        let size = hit.closest.bary[0] * s[0] + (1.0 - hit.closest.bary[0]) * s[1];
        Some(Hit {
            point: hit.closest.point,
            index: hit.triangle,
            dist: hit.closest.dist2.sqrt(),
            size,
            contact: false,
        })
    }

    /// Largest distance from points spread along segment `a`–`b` (both ends
    /// included, `n` intervals) to line `line`.
    pub fn chord_distance(&self, a: [f64; 3], b: [f64; 3], line: u32, n: usize) -> f64 {
        let mut worst: f64 = 0.0;
        let mut hint = u32::MAX;
        for k in 0..=n {
            let p = lerp(a, b, k as f64 / n as f64);
            match self.on_line(p, line, hint) {
                Some(h) => {
                    worst = worst.max(h.dist);
                    hint = h.index;
                }
                None => return f64::INFINITY,
            }
        }
        worst
    }
}
