//! Bounding-volume hierarchy over triangles: binned SAH build, flattened
//! depth-first node array (left child stored right after its parent), triangle
//! corners copied into leaf order so a leaf is one contiguous read.
//!
//! Build: O(F log F) time, parallel over subtrees. Memory: 64 bytes per node
//! (one cache line; 1.1–1.5 nodes per triangle with the SAH's small leaves,
//! measured on a random soup and a smooth plate) plus 76 bytes per triangle,
//! plus the wide view's once built.
//!
//! Closest-point query: exact (f64 point–triangle distance), ties broken by the
//! lowest triangle index, so the answer depends only on the point — never on the
//! traversal order or a hint. Expected O(log F) for points near the surface.
//! [`Bvh::closest_wide`] (a grid's size queries) descends a 4-wide view of
//! this tree with f32 boxes rounded outward (module `wide`, built on first
//! use); every other search descends the binary nodes.

use super::wide::WideBvh;
use crate::geometry::{closest_point_triangle, Aabb, ClosestPoint};
use arrayvec::ArrayVec;
use std::sync::OnceLock;

/// Largest leaf the SAH may choose.
const MAX_LEAF: usize = 4;
/// SAH bins per split.
const BINS: usize = 16;
/// Below this many triangles a subtree is built on the current thread.
const PARALLEL_CUTOFF: usize = 8192;
/// Depth after which splits are median splits (guarantees [`MAX_DEPTH`]).
const SAH_DEPTH: usize = 60;
/// Upper bound on the tree depth, so traversal stacks can be fixed arrays.
pub const MAX_DEPTH: usize = 128;
/// [`Bvh::node_labels`]' label of a node whose triangles' labels differ.
pub const MIXED_LABEL: u32 = u32::MAX;

/// One node of the flattened tree (one cache line).
#[derive(Debug, Clone, Copy)]
#[repr(align(64))]
pub struct Node {
    /// Bounds of every triangle below.
    pub bbox: Aabb,
    /// Leaf: first primitive (index into [`Bvh::prim_triangle`]). Inner: index of the right child
    /// (the left child is the next node).
    pub start: u32,
    /// Leaf: number of primitives (> 0). Inner: 0.
    pub count: u32,
}

impl Node {
    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// The hierarchy. Immutable after [`Bvh::build`].
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    /// Flattened nodes, root first.
    pub nodes: Vec<Node>,
    /// Triangle index of each primitive slot (leaf order).
    pub prim_triangle: Vec<u32>,
    /// The corners of each primitive, in leaf order.
    pub prim_corners: Vec<[[f64; 3]; 3]>,
    /// Primitive slot of each triangle (inverse of `prim_triangle`).
    pub triangle_prim: Vec<u32>,
    /// Largest absolute coordinate of the root box (scale of rounding errors).
    pub coord_scale: f64,
    /// The 4-wide view [`Bvh::closest_wide`] descends, derived from `nodes`
    /// on its first call (see [`super::wide`]).
    pub(super) wide: OnceLock<WideBvh>,
}

/// Where a search reads the corners of a primitive slot (leaf order): the
/// tree's own [`Bvh::prim_corners`], or another structure holding the same
/// triangles (see [`Bvh::closest_with_corners`]).
pub(crate) trait Corners {
    /// The corners of the triangle in primitive slot `slot`.
    fn corners(&self, slot: usize) -> &[[f64; 3]; 3];
}

impl Corners for [[[f64; 3]; 3]] {
    #[inline(always)]
    fn corners(&self, slot: usize) -> &[[f64; 3]; 3] {
        &self[slot]
    }
}

/// Best candidate of a closest-point search.
pub(super) struct Best {
    tri: u32,
    cp: ClosestPoint,
    /// Squared distance of the best candidate (or the initial bound).
    d2: f64,
    /// Boxes farther than this (squared) are pruned: `d2` plus rounding slack.
    pub(super) limit: f64,
    /// Rounding allowance of squared distances (see [`Bvh::pad`]).
    pad: f64,
}

impl Best {
    fn new(p: [f64; 3], bound2: f64, pad: f64) -> Best {
        Best {
            tri: u32::MAX,
            cp: ClosestPoint {
                point: p,
                bary: [1.0, 0.0, 0.0],
                dist2: f64::INFINITY,
            },
            d2: bound2,
            limit: padded(bound2, pad),
            pad,
        }
    }

    /// Keeps `cp` (on triangle `tri`) if it is closer, or equally close with a
    /// lower triangle index.
    #[inline(always)]
    pub(super) fn offer(&mut self, tri: u32, cp: ClosestPoint) {
        if cp.dist2 < self.d2 || (cp.dist2 == self.d2 && tri < self.tri) {
            if cp.dist2 != self.d2 {
                self.limit = padded(cp.dist2, self.pad);
            }
            self.d2 = cp.dist2;
            self.tri = tri;
            self.cp = cp;
        }
    }

    /// The answer: the best candidate, if any.
    pub(super) fn hit(&self) -> Option<ClosestHit> {
        (self.tri != u32::MAX).then_some(ClosestHit {
            triangle: self.tri,
            closest: self.cp,
        })
    }
}

/// `d2` grown by the allowance `pad` of [`Bvh::pad`] (no square root on the
/// search's critical path); infinity stays infinity.
#[inline(always)]
fn padded(d2: f64, pad: f64) -> f64 {
    d2 * (1.0 + 1e-12) + pad
}

/// Result of a closest-point query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestHit {
    /// Index of the closest triangle.
    pub triangle: u32,
    /// The closest point on it.
    pub closest: ClosestPoint,
}

#[derive(Clone, Copy)]
struct Prim {
    tri: u32,
    bbox: Aabb,
    centroid: [f64; 3],
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (indices into `vertices`).
    /// An empty triangle list gives an empty tree. O(F log F).
    pub fn build(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Bvh {
        let mut prims: Vec<Prim> = triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let bbox = Aabb::from_points(t.iter().map(|&v| &vertices[v as usize]));
                Prim {
                    tri: i as u32,
                    bbox,
                    centroid: bbox.center(),
                }
            })
            .collect();
        if prims.is_empty() {
            return Bvh::default();
        }
        let nodes = build_rec(&mut prims, 0, 0);
        let coord_scale = coord_scale(&nodes[0].bbox);
        let prim_triangle: Vec<u32> = prims.iter().map(|p| p.tri).collect();
        let prim_corners = prim_triangle
            .iter()
            .map(|&t| triangles[t as usize].map(|v| vertices[v as usize]))
            .collect();
        let mut triangle_prim = vec![0u32; triangles.len()];
        for (slot, &t) in prim_triangle.iter().enumerate() {
            triangle_prim[t as usize] = slot as u32;
        }
        Bvh {
            wide: OnceLock::new(),
            nodes,
            prim_triangle,
            prim_corners,
            triangle_prim,
            coord_scale,
        }
    }

    /// Bytes of heap memory held by the tree.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
            + self.prim_triangle.len() * 4
            + self.triangle_prim.len() * 4
            + self.prim_corners.len() * std::mem::size_of::<[[f64; 3]; 3]>()
            + self.wide.get().map_or(0, WideBvh::memory_bytes)
    }

    /// Depth of the tree (1 for a single leaf).
    pub fn depth(&self) -> usize {
        fn rec(n: &[Node], i: usize) -> usize {
            if n[i].is_leaf() {
                1
            } else {
                1 + rec(n, i + 1).max(rec(n, n[i].start as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            rec(&self.nodes, 0)
        }
    }

    /// Exact closest point on the surface to `p`, or `None` for an empty tree.
    ///
    /// `hint` (a triangle index, typically the previous answer of a nearby query)
    /// seeds the search bound; it changes the time, never the answer. An
    /// out-of-range hint is ignored. Expected O(log F); O(F) worst case.
    #[inline]
    pub fn closest(&self, p: [f64; 3], hint: Option<u32>) -> Option<ClosestHit> {
        self.closest_filtered(p, hint, |_| true)
    }

    /// [`Bvh::closest`] on the tree's 4-wide view (module `wide`: f32 boxes
    /// rounded outward, four box tests per node visit): the same answer bit
    /// for bit; faster where a search tests many boxes (on the harness's
    /// dense grids, 1 thread: 1.06–1.41× for points uniform in the box, up
    /// to 1.75× near the surface in random order), about the same to 1.3×
    /// on a coherent walk. The first call builds the view, O(nodes),
    /// 33–45 bytes per triangle ([`Bvh::memory_bytes`] counts it once
    /// built); the size queries of a [`crate::mesh::Grid`] use it. Expected
    /// O(log F).
    pub fn closest_wide(&self, p: [f64; 3], hint: Option<u32>) -> Option<ClosestHit> {
        self.search_wide(p, hint, f64::INFINITY, |_| true, &self.prim_corners[..])
    }

    /// The 4-wide view, built on first use. O(nodes) once.
    pub(super) fn wide(&self) -> &WideBvh {
        self.wide.get_or_init(|| WideBvh::build(&self.nodes))
    }

    /// [`Bvh::closest`] among the triangles accepted by `keep` (ties to the
    /// lowest index, so the answer depends only on `p`); the hint is used only
    /// when accepted. `None` when nothing is accepted. Expected O(log F) when
    /// most triangles are accepted; O(F) worst case.
    pub fn closest_filtered(
        &self,
        p: [f64; 3],
        hint: Option<u32>,
        keep: impl Fn(u32) -> bool,
    ) -> Option<ClosestHit> {
        self.search(
            p,
            hint,
            f64::INFINITY,
            keep,
            |_| true,
            &self.prim_corners[..],
        )
    }

    /// [`Bvh::closest_filtered`] restricted to distances below `max_distance`
    /// (`None` when no accepted triangle is that close). Only the nodes within
    /// `max_distance` of `p` are visited: O(log F + k) for a small radius with
    /// k triangles inside it.
    pub fn closest_filtered_within(
        &self,
        p: [f64; 3],
        max_distance: f64,
        keep: impl Fn(u32) -> bool,
    ) -> Option<ClosestHit> {
        self.search(
            p,
            None,
            max_distance * max_distance,
            keep,
            |_| true,
            &self.prim_corners[..],
        )
    }

    /// [`Bvh::closest_filtered_within`] that also skips every node for which
    /// `keep_node(node)` is false: the caller's promise that `keep` accepts
    /// no triangle below it (e.g. a node whose triangles all belong to an
    /// excluded body, [`Bvh::node_labels`]), so the answer is the same and
    /// only the time changes. O(log F + k) for k accepted triangles within
    /// reach and the nodes not pruned.
    pub fn closest_filtered_within_pruned(
        &self,
        p: [f64; 3],
        max_distance: f64,
        keep: impl Fn(u32) -> bool,
        keep_node: impl Fn(usize) -> bool,
    ) -> Option<ClosestHit> {
        self.search(
            p,
            None,
            max_distance * max_distance,
            keep,
            keep_node,
            &self.prim_corners[..],
        )
    }

    /// For per-triangle labels `tri_label` (a body, say), the label shared by
    /// every triangle below each node, or [`MIXED_LABEL`] where they differ.
    /// O(nodes).
    pub fn node_labels(&self, tri_label: &[u32]) -> Vec<u32> {
        self.fold_subtrees(tri_label, |a, b| if a == b { a } else { MIXED_LABEL })
    }

    /// [`Bvh::closest`] with the corners of each primitive slot read from
    /// `corners` instead of [`Bvh::prim_corners`] (which may then be
    /// empty): for a tree that shares its triangles' corners with another
    /// structure. The corners must be those the tree was built over, in
    /// their order, for the answer to be [`Bvh::closest`]'s. Expected
    /// O(log F).
    pub(crate) fn closest_with_corners(
        &self,
        p: [f64; 3],
        hint: Option<u32>,
        corners: &impl Corners,
    ) -> Option<ClosestHit> {
        self.search(p, hint, f64::INFINITY, |_| true, |_| true, corners)
    }

    /// The start of a search at `p` from the bound `bound2` (squared): the
    /// `hint` triangle offered first when it is in range and accepted.
    #[inline(always)]
    pub(super) fn seed(
        &self,
        p: [f64; 3],
        hint: Option<u32>,
        bound2: f64,
        keep: &impl Fn(u32) -> bool,
        corners: &(impl Corners + ?Sized),
    ) -> Best {
        let mut best = Best::new(p, bound2, self.pad(&p));
        // In range first: `keep` may index by triangle.
        if let Some(h) = hint.filter(|&h| (h as usize) < self.triangle_prim.len() && keep(h)) {
            let c = corners.corners(self.triangle_prim[h as usize] as usize);
            best.offer(h, closest_point_triangle(p, c[0], c[1], c[2]));
        }
        best
    }

    /// Branch and bound from the bound `bound2` (squared distance), seeded by
    /// `hint`: top-down from the root, nearer child first, the corners of
    /// each primitive slot read from `corners`.
    fn search(
        &self,
        p: [f64; 3],
        hint: Option<u32>,
        bound2: f64,
        keep: impl Fn(u32) -> bool,
        keep_node: impl Fn(usize) -> bool,
        corners: &(impl Corners + ?Sized),
    ) -> Option<ClosestHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = self.seed(p, hint, bound2, &keep, corners);
        if self.nodes[0].bbox.distance2(&p) <= best.limit {
            self.descend(&p, &mut best, &keep, &keep_node, corners);
        }
        best.hit()
    }

    /// Some triangle whose (computed) squared distance to `p` is at most `r2`,
    /// or `None` when there is none. The search stops at the first one found,
    /// the `hint` triangle tried first: a cheap test of "is `p` within `r` of
    /// the surface". O(log F) expected when the answer is yes near the hint;
    /// O(log F + k) otherwise, k = triangles whose boxes come within `r`.
    pub fn any_within(&self, p: [f64; 3], r2: f64, hint: Option<u32>) -> Option<u32> {
        let test = |slot: usize| {
            let c = &self.prim_corners[slot];
            closest_point_triangle(p, c[0], c[1], c[2]).dist2 <= r2
        };
        if let Some(&slot) = hint.and_then(|h| self.triangle_prim.get(h as usize)) {
            if test(slot as usize) {
                return hint;
            }
        }
        let mut found = None;
        self.visit_within(
            p,
            r2,
            |_| true,
            |slot| {
                let hit = test(slot);
                if hit {
                    found = Some(self.prim_triangle[slot]);
                }
                hit
            },
        );
        found
    }

    /// Visits the primitive slots of every leaf whose box lies within `r2`
    /// (squared) of `p`, padded for rounding as the searches prune, below
    /// nodes that `keep_node` accepts, nearer children first, until `visit`
    /// returns true; true when it did. The range search behind
    /// [`Bvh::any_within`] and the contact lists. O(log F + k) for k leaves
    /// within reach.
    pub fn visit_within(
        &self,
        p: [f64; 3],
        r2: f64,
        keep_node: impl Fn(usize) -> bool,
        mut visit: impl FnMut(usize) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let limit = padded(r2, self.pad(&p));
        if self.nodes[0].bbox.distance2(&p) > limit {
            return false;
        }
        let mut stack: ArrayVec<u32, { MAX_DEPTH + 1 }> = ArrayVec::new();
        stack.push(0);
        while let Some(ni) = stack.pop() {
            let ni = ni as usize;
            if !keep_node(ni) {
                continue;
            }
            let n = &self.nodes[ni];
            if n.is_leaf() {
                let s = n.start as usize;
                if (s..s + n.count as usize).any(&mut visit) {
                    return true;
                }
                continue;
            }
            // Children within reach, the nearer popped first.
            let (near, dn, far, df) = self.children_by_distance(ni, &p);
            // One net entry per level: within capacity by the depth bound.
            if df <= limit {
                stack.push(far as u32);
            }
            if dn <= limit {
                stack.push(near as u32);
            }
        }
        false
    }

    /// Scale of the rounding errors of distances near `p`: `1e-12` of the
    /// largest coordinate magnitude (the root box's or `p`'s). Distances
    /// computed near `p` err by far less. O(1).
    #[inline]
    pub fn rounding_scale(&self, p: &[f64; 3]) -> f64 {
        1e-12 * p.iter().fold(self.coord_scale, |m, c| m.max(c.abs()))
    }

    /// Rounding allowance of squared distances near `p`. Distances computed
    /// near `p` err by far less than `s = 1e-12 · max |coordinate|`, so a box is
    /// pruned only when farther than `(√d2 + s)²` for the best `d2`: a triangle
    /// whose computed distance ties the best is never skipped. As `√d2 ≤ R`,
    /// the largest distance from `p` to the root box, `(√d2 + s)² ≤ d2 + s(2R + s)`,
    /// the returned `s(2R + s)`.
    #[inline]
    pub(super) fn pad(&self, p: &[f64; 3]) -> f64 {
        let s = self.rounding_scale(p);
        let b = &self.nodes[0].bbox;
        let mut r2 = 0.0;
        for k in 0..3 {
            let f = (p[k] - b.min[k]).abs().max((p[k] - b.max[k]).abs());
            r2 += f * f;
        }
        s * (2.0 * r2.sqrt() * (1.0 + 1e-12) + s)
    }

    /// Scans the primitives of leaf `leaf`.
    #[inline]
    fn scan_leaf(
        &self,
        leaf: usize,
        p: &[f64; 3],
        best: &mut Best,
        keep: &impl Fn(u32) -> bool,
        corners: &(impl Corners + ?Sized),
    ) {
        let n = &self.nodes[leaf];
        self.scan_slots(n.start as usize, n.count as usize, p, best, keep, corners);
    }

    /// Offers the accepted triangles of the primitive slots `s..s + count`.
    #[inline]
    pub(super) fn scan_slots(
        &self,
        s: usize,
        count: usize,
        p: &[f64; 3],
        best: &mut Best,
        keep: &impl Fn(u32) -> bool,
        corners: &(impl Corners + ?Sized),
    ) {
        for slot in s..s + count {
            let tri = self.prim_triangle[slot];
            if keep(tri) {
                let c = corners.corners(slot);
                best.offer(tri, closest_point_triangle(*p, c[0], c[1], c[2]));
            }
        }
    }

    /// The two children of inner node `node` as (nearer, its squared box
    /// distance to `p`, farther, its distance); ties to the left child.
    #[inline(always)]
    fn children_by_distance(&self, node: usize, p: &[f64; 3]) -> (usize, f64, usize, f64) {
        let (l, r) = (node + 1, self.nodes[node].start as usize);
        let dl = self.nodes[l].bbox.distance2(p);
        let dr = self.nodes[r].bbox.distance2(p);
        if dl <= dr {
            (l, dl, r, dr)
        } else {
            (r, dr, l, dl)
        }
    }

    /// Top-down search from the root (whose box the caller checked).
    fn descend(
        &self,
        p: &[f64; 3],
        best: &mut Best,
        keep: &impl Fn(u32) -> bool,
        keep_node: &impl Fn(usize) -> bool,
        corners: &(impl Corners + ?Sized),
    ) {
        // Uninitialised storage: zeroing a fixed array costs more than the walk.
        let mut stack: ArrayVec<(u32, f64), MAX_DEPTH> = ArrayVec::new();
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if !keep_node(node) {
                // Nothing below is accepted: pop the next node.
            } else if n.is_leaf() {
                self.scan_leaf(node, p, best, keep, corners);
            } else {
                let (near, dn, far, df) = self.children_by_distance(node, p);
                if dn <= best.limit {
                    if df <= best.limit {
                        // At most one entry per level: the depth bound keeps it in capacity.
                        stack.push((far as u32, df));
                    }
                    node = near;
                    continue;
                }
            }
            // Pop the next node still within the bound.
            let mut next = None;
            while let Some((nd, d)) = stack.pop() {
                if d <= best.limit {
                    next = Some(nd as usize);
                    break;
                }
            }
            match next {
                Some(nd) => node = nd,
                None => break,
            }
        }
    }

    /// For per-triangle values `tri_min`, the minimum over each node's subtree
    /// (used as the lower bound of branch-and-bound queries). O(nodes).
    pub fn node_minima(&self, tri_min: &[f64]) -> Vec<f64> {
        self.fold_subtrees(tri_min, f64::min)
    }

    /// Per node, `merge` folded over the values `per_tri` of the triangles
    /// below it (leaves hold at least one). O(nodes).
    fn fold_subtrees<T: Copy>(&self, per_tri: &[T], merge: impl Fn(T, T) -> T) -> Vec<T> {
        let Some(&first) = per_tri.first() else {
            return Vec::new();
        };
        let mut out = vec![first; self.nodes.len()];
        // Children come after their parent: a reverse sweep sees children first.
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            out[i] = if n.is_leaf() {
                let s = n.start as usize;
                let mut values = self.prim_triangle[s..s + n.count as usize]
                    .iter()
                    .map(|&t| per_tri[t as usize]);
                let v0 = values.next().unwrap_or(first);
                values.fold(v0, &merge)
            } else {
                merge(out[i + 1], out[n.start as usize])
            };
        }
        out
    }
}

/// Largest absolute coordinate of the root box `b` ([`Bvh::coord_scale`]).
pub(super) fn coord_scale(b: &Aabb) -> f64 {
    b.min
        .iter()
        .chain(&b.max)
        .fold(0.0f64, |m, c| m.max(c.abs()))
}

/// Builds the subtree over `prims` (which start at slot `offset` of the final
/// primitive array) and returns its nodes with absolute indices relative to the
/// subtree root at index 0 (caller shifts them).
fn build_rec(prims: &mut [Prim], offset: usize, depth: usize) -> Vec<Node> {
    let mut bbox = Aabb::EMPTY;
    let mut cbox = Aabb::EMPTY;
    for p in prims.iter() {
        bbox.merge(&p.bbox);
        cbox.grow(&p.centroid);
    }
    let n = prims.len();
    let leaf = |bbox| {
        vec![Node {
            bbox,
            start: offset as u32,
            count: n as u32,
        }]
    };
    if n <= 1 {
        return leaf(bbox);
    }
    let ext = crate::geometry::sub(cbox.max, cbox.min);
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    let mut mid = None;
    if depth < SAH_DEPTH && ext[axis] > 0.0 {
        mid = sah_split(prims, &bbox, &cbox, axis);
        if mid.is_none() && n <= MAX_LEAF {
            return leaf(bbox);
        }
    } else if n <= MAX_LEAF {
        return leaf(bbox);
    }
    let mid = match mid {
        Some(m) => m,
        None => {
            // Median split along the axis (total order: centroid, then triangle index).
            let m = n / 2;
            prims.select_nth_unstable_by(m, |a, b| {
                a.centroid[axis]
                    .total_cmp(&b.centroid[axis])
                    .then(a.tri.cmp(&b.tri))
            });
            m
        }
    };
    let (lp, rp) = prims.split_at_mut(mid);
    let (left, right) = if n > PARALLEL_CUTOFF {
        rayon::join(
            || build_rec(lp, offset, depth + 1),
            || build_rec(rp, offset + mid, depth + 1),
        )
    } else {
        (
            build_rec(lp, offset, depth + 1),
            build_rec(rp, offset + mid, depth + 1),
        )
    };
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    let right_index = 1 + left.len();
    nodes.push(Node {
        bbox,
        start: right_index as u32,
        count: 0,
    });
    let shift = |mut nd: Node, by: usize| {
        if !nd.is_leaf() {
            nd.start += by as u32;
        }
        nd
    };
    nodes.extend(left.into_iter().map(|nd| shift(nd, 1)));
    nodes.extend(right.into_iter().map(|nd| shift(nd, right_index)));
    nodes
}

/// Binned SAH: partitions `prims` in place and returns the split position, or
/// `None` when no split is cheaper than a leaf of at most [`MAX_LEAF`] items.
fn sah_split(prims: &mut [Prim], bbox: &Aabb, cbox: &Aabb, axis: usize) -> Option<usize> {
    let n = prims.len();
    let lo = cbox.min[axis];
    let inv = BINS as f64 / (cbox.max[axis] - lo);
    let bin_of = |p: &Prim| (((p.centroid[axis] - lo) * inv) as usize).min(BINS - 1);
    let mut counts = [0usize; BINS];
    let mut boxes = [Aabb::EMPTY; BINS];
    for p in prims.iter() {
        let b = bin_of(p);
        counts[b] += 1;
        boxes[b].merge(&p.bbox);
    }
    // Sweep from the right to get suffix areas.
    let mut right_area = [0.0; BINS];
    let mut acc = Aabb::EMPTY;
    for b in (1..BINS).rev() {
        acc.merge(&boxes[b]);
        right_area[b] = acc.area();
    }
    let mut best = (f64::INFINITY, 0usize);
    let mut lbox = Aabb::EMPTY;
    let mut lcount = 0usize;
    for b in 0..BINS - 1 {
        lbox.merge(&boxes[b]);
        lcount += counts[b];
        let rcount = n - lcount;
        if lcount == 0 || rcount == 0 {
            continue;
        }
        let cost = lbox.area() * lcount as f64 + right_area[b + 1] * rcount as f64;
        if cost < best.0 {
            best = (cost, b);
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let parent_area = bbox.area();
    let split_cost = 1.0
        + if parent_area > 0.0 {
            best.0 / parent_area
        } else {
            0.0
        };
    if n <= MAX_LEAF && split_cost >= n as f64 {
        return None;
    }
    // Stable-order partition: left bins first.
    let split_bin = best.1;
    let mut i = 0;
    for j in 0..n {
        if bin_of(&prims[j]) <= split_bin {
            prims.swap(i, j);
            i += 1;
        }
    }
    if i == 0 || i == n {
        None
    } else {
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::dist2;
    use crate::test_shapes::triangle_soup as random_soup;
    use rand::{Rng, SeedableRng};

    #[test]
    fn closest_matches_brute_force_with_and_without_hint() {
        let (v, t) = random_soup(3000, 1);
        let bvh = Bvh::build(&v, &t);
        assert!(bvh.depth() <= MAX_DEPTH);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        for _ in 0..500 {
            let p = [
                rng.gen_range(-0.5..1.5),
                rng.gen_range(-0.5..1.5),
                rng.gen_range(-0.5..1.5),
            ];
            let mut best = (f64::INFINITY, u32::MAX);
            for (i, tri) in t.iter().enumerate() {
                let cp = closest_point_triangle(
                    p,
                    v[tri[0] as usize],
                    v[tri[1] as usize],
                    v[tri[2] as usize],
                );
                if cp.dist2 < best.0 {
                    best = (cp.dist2, i as u32);
                }
            }
            let hit = bvh.closest(p, None).unwrap();
            assert_eq!(hit.triangle, best.1);
            assert_eq!(hit.closest.dist2, best.0);
            let hinted = bvh.closest(p, Some(rng.gen_range(0..3000))).unwrap();
            assert_eq!(hinted, hit);
            assert!(dist2(hit.closest.point, p) == hit.closest.dist2);
        }
    }

    #[test]
    fn any_within_agrees_with_the_closest_distance() {
        let (v, t) = random_soup(2000, 4);
        let bvh = Bvh::build(&v, &t);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut yes, mut no) = (0, 0);
        for _ in 0..400 {
            let p = [
                rng.gen_range(-0.5..1.5),
                rng.gen_range(-0.5..1.5),
                rng.gen_range(-0.5..1.5),
            ];
            let d2 = bvh.closest(p, None).unwrap().closest.dist2;
            let r2 = d2 * rng.gen_range(0.5..1.5);
            let hint = rng.gen_bool(0.5).then(|| rng.gen_range(0..2000));
            match bvh.any_within(p, r2, hint) {
                Some(tri) => {
                    yes += 1;
                    assert!(d2 <= r2);
                    let c = t[tri as usize].map(|i| v[i as usize]);
                    assert!(closest_point_triangle(p, c[0], c[1], c[2]).dist2 <= r2);
                }
                None => {
                    no += 1;
                    assert!(d2 > r2);
                }
            }
            assert!(
                bvh.any_within(p, d2, None).is_some(),
                "the closest is within"
            );
        }
        assert!(yes > 50 && no > 50, "both answers exercised: {yes} / {no}");
        assert!(Bvh::build(&v, &[])
            .any_within([0.0; 3], 1.0, None)
            .is_none());
    }

    #[test]
    fn identical_centroids_and_tiny_inputs() {
        // Many copies of the same triangle: forces median splits.
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let t = vec![[0u32, 1, 2]; 1000];
        let bvh = Bvh::build(&v, &t);
        assert!(bvh.depth() <= MAX_DEPTH);
        let hit = bvh.closest([0.2, 0.2, 1.0], None).unwrap();
        assert_eq!(hit.triangle, 0, "ties go to the lowest index");
        assert_eq!(bvh.closest([0.2, 0.2, 1.0], Some(999)).unwrap().triangle, 0);
        let one = Bvh::build(&v, &t[..1]);
        assert_eq!(one.nodes.len(), 1);
        assert!(Bvh::build(&v, &[]).closest([0.0; 3], None).is_none());
    }

    #[test]
    fn node_minima_are_subtree_minima() {
        let (v, t) = random_soup(500, 3);
        let bvh = Bvh::build(&v, &t);
        let vals: Vec<f64> = (0..t.len()).map(|i| ((i * 7919) % 1000) as f64).collect();
        let m = bvh.node_minima(&vals);
        assert_eq!(m[0], 0.0);
        for (i, n) in bvh.nodes.iter().enumerate() {
            if !n.is_leaf() {
                assert_eq!(m[i], m[i + 1].min(m[n.start as usize]));
            }
        }
    }

    #[test]
    fn pruning_excluded_labels_keeps_every_answer() {
        let (v, t) = random_soup(2000, 5);
        let bvh = Bvh::build(&v, &t);
        // Labels by region (as bodies are), with a few scattered ones.
        let label: Vec<u32> = (0..t.len())
            .map(|i| {
                let c = v[t[i][0] as usize];
                if i % 97 == 0 {
                    3
                } else {
                    (c[0] * 3.0) as u32
                }
            })
            .collect();
        let nodes = bvh.node_labels(&label);
        for (i, n) in bvh.nodes.iter().enumerate() {
            if nodes[i] != MIXED_LABEL && n.is_leaf() {
                let s = n.start as usize;
                for &tri in &bvh.prim_triangle[s..s + n.count as usize] {
                    assert_eq!(label[tri as usize], nodes[i]);
                }
            }
        }
        assert!(nodes.iter().any(|&l| l != MIXED_LABEL));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        for _ in 0..400 {
            let p = [rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()];
            let own = rng.gen_range(0..4u32);
            let reach = 0.3 * rng.gen::<f64>();
            let keep = |t: u32| label[t as usize] != own;
            assert_eq!(
                bvh.closest_filtered_within_pruned(p, reach, keep, |n| nodes[n] != own),
                bvh.closest_filtered_within(p, reach, keep)
            );
        }
    }
}
