//! One bounding-volume hierarchy per label: the exact closest point among the
//! triangles of one label (a smooth patch, say) without the triangles of the
//! others in the way.
//!
//! # Why not filter the one tree
//!
//! [`Bvh::closest_filtered`] prunes by box distance only, so every triangle
//! of another label that lies closer than the answer is reached and
//! rejected. Where labels interleave in space, which is what a thin sheet
//! (its two sides are two patches closer together than a triangle is wide)
//! or two bodies lying on each other do, a leaf holds triangles of both and
//! no subtree can be skipped by its labels ([`Bvh::node_labels`]) either:
//! on trimesh_fm1_satellite's dense grid a filtered search scanned about 290
//! triangles and 370 nodes to accept 4.4. A tree per label holds only what
//! the search may accept.
//!
//! # Cost and ties
//!
//! Build: the triangles grouped by label (ascending index within a group),
//! one [`Bvh::build`] per label, labels in parallel: O(F log F) in all.
//! Memory: the trees' nodes (64 bytes each) and slot maps (8 bytes per
//! triangle) plus 4 bytes per triangle for the group lists; the trees keep no corners
//! of their own but read the whole grid's tree's ([`Bvh::prim_corners`],
//! two more indirections per triangle tested), which saves 72 bytes per
//! triangle. A query is a search of one tree, O(log F_label) expected.
//! Within a group, local triangle order is global order and the corners
//! are the grid tree's, in the triangles' own order, so an answer is
//! [`Bvh::closest_filtered`]'s with the same filter bit for bit: the
//! triangle (ties to the lowest index), the closest point and the
//! distance.

use super::bvh::{Bvh, ClosestHit, Corners};
use rayon::prelude::*;

/// A [`Bvh`] per label over the triangles carrying it. Immutable after
/// [`LabelForest::build`].
#[derive(Debug, Clone, Default)]
pub struct LabelForest {
    /// Start of each label's triangles in `members` (one more than labels).
    offsets: Vec<u32>,
    /// Triangle indices grouped by label, ascending within a group.
    members: Vec<u32>,
    /// The tree of each label, over its group (local index = position in
    /// the group).
    trees: Vec<Bvh>,
}

impl LabelForest {
    /// Builds a tree per label `0..label_count` over `triangles` (indices
    /// into `vertices`), `labels[t]` being triangle `t`'s label. Triangles
    /// whose label is out of range are left out. O(F log F), parallel over
    /// labels.
    pub fn build(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        labels: &[u32],
        label_count: u32,
    ) -> LabelForest {
        let n = label_count as usize;
        let mut offsets = vec![0u32; n + 1];
        for &l in labels.iter().take(triangles.len()) {
            if (l as usize) < n {
                offsets[l as usize + 1] += 1;
            }
        }
        for k in 0..n {
            offsets[k + 1] += offsets[k];
        }
        let mut fill = offsets.clone();
        let mut members = vec![0u32; offsets[n] as usize];
        for (t, &l) in labels.iter().take(triangles.len()).enumerate() {
            if (l as usize) < n {
                members[fill[l as usize] as usize] = t as u32;
                fill[l as usize] += 1;
            }
        }
        let trees = (0..n)
            .into_par_iter()
            .with_max_len(1)
            .map(|l| {
                let group = &members[offsets[l] as usize..offsets[l + 1] as usize];
                let local: Vec<[u32; 3]> = group.iter().map(|&t| triangles[t as usize]).collect();
                let mut tree = Bvh::build(vertices, &local);
                // The corners are read from the whole grid's tree.
                tree.prim_corners = Vec::new();
                tree
            })
            .collect();
        LabelForest {
            offsets,
            members,
            trees,
        }
    }

    /// The exact closest point of `p` among the triangles labelled `label`
    /// (triangle indices global), seeded by triangle `hint` when it carries
    /// the label: [`Bvh::closest_filtered`] with the filter "label is
    /// `label`", bit for bit. `bvh` is the tree over the same vertices and
    /// triangles, whose corners the search reads. `None` when no triangle
    /// carries the label. O(log F) expected.
    pub fn closest(
        &self,
        bvh: &Bvh,
        p: [f64; 3],
        label: u32,
        hint: Option<u32>,
    ) -> Option<ClosestHit> {
        let l = label as usize;
        let tree = self.trees.get(l)?;
        let group = &self.members[self.offsets[l] as usize..self.offsets[l + 1] as usize];
        let local_hint = hint.and_then(|h| group.binary_search(&h).ok().map(|i| i as u32));
        let corners = GroupCorners { tree, group, bvh };
        let hit = tree.closest_with_corners(p, local_hint, &corners)?;
        Some(ClosestHit {
            triangle: group[hit.triangle as usize],
            closest: hit.closest,
        })
    }
}

/// The corners of a label's tree, read from the whole grid's tree: slot →
/// local triangle → global triangle → the grid tree's slot.
struct GroupCorners<'a> {
    tree: &'a Bvh,
    group: &'a [u32],
    bvh: &'a Bvh,
}

impl Corners for GroupCorners<'_> {
    #[inline(always)]
    fn corners(&self, slot: usize) -> &[[f64; 3]; 3] {
        let t = self.group[self.tree.prim_triangle[slot] as usize];
        &self.bvh.prim_corners[self.bvh.triangle_prim[t as usize] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::{rng, unit_square};

    #[test]
    fn answers_are_the_filtered_searches_bit_for_bit() {
        // Two wavy sheets a hair apart with labels by stripes and by sheet,
        // so labels interleave in space; every label's answers equal the
        // one tree's filtered search, ties and all.
        let (mut v, mut t) = unit_square(14, |x, y| 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let (v2, t2) = unit_square(14, |x, y| 1e-4 + 0.05 * (7.0 * x).sin() * (5.0 * y).cos());
        let base = v.len() as u32;
        v.extend(v2);
        t.extend(t2.iter().map(|f| f.map(|i| i + base)));
        let half = t.len() / 2;
        let labels: Vec<u32> = (0..t.len())
            .map(|k| (k >= half) as u32 * 3 + (k % half % 7 == 0) as u32)
            .collect();
        let bvh = Bvh::build(&v, &t);
        let forest = LabelForest::build(&v, &t, &labels, 5);
        let mut seed = 7u64;
        for _ in 0..2000 {
            let p = [
                1.4 * rng(&mut seed) - 0.2,
                1.4 * rng(&mut seed) - 0.2,
                0.6 * rng(&mut seed) - 0.3,
            ];
            for label in 0..6u32 {
                let hint = Some((rng(&mut seed) * (t.len() + 5) as f64) as u32);
                let want = bvh.closest_filtered(p, None, |u| labels[u as usize] == label);
                let got = forest.closest(&bvh, p, label, hint);
                match (want, got) {
                    (None, None) => assert!(label == 2 || label >= 5),
                    (Some(w), Some(g)) => {
                        assert_eq!(w.triangle, g.triangle);
                        assert_eq!(w.closest.point, g.closest.point);
                        assert_eq!(w.closest.bary, g.closest.bary);
                        assert_eq!(w.closest.dist2.to_bits(), g.closest.dist2.to_bits());
                    }
                    _ => panic!("label {label}: {want:?} against {got:?}"),
                }
            }
        }
        // Equidistant triangles (a point above a shared vertex of a flat
        // sheet) go to the lowest index, as the one tree's do.
        let (v, t) = unit_square(4, |_, _| 0.0);
        let labels = vec![0; t.len()];
        let forest = LabelForest::build(&v, &t, &labels, 1);
        let bvh = Bvh::build(&v, &t);
        let p = [0.5, 0.5, 1.0];
        assert_eq!(
            forest
                .closest(&bvh, p, 0, Some(t.len() as u32 - 1))
                .unwrap()
                .triangle,
            bvh.closest(p, None).unwrap().triangle
        );
    }
}
