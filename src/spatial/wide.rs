//! The 4-wide view of a [`Bvh`] that [`Bvh::closest_wide`] descends:
//! each node holds the boxes of up to four children in f32, rounded outward,
//! so one node visit tests four boxes in a few vector instructions and reads
//! two cache lines, where the binary tree tests two boxes per node in f64.
//!
//! **Shape.** Built from the binary tree by collapsing: a wide node starts
//! with its binary node's two children and repeatedly replaces the inner
//! child with the largest box area by that child's two children, until it
//! holds four or only leaves remain. Each lane is then either another wide
//! node or a binary leaf (a run of primitive slots): the leaves, the
//! primitive order and the corners are the binary tree's, so the triangle
//! tests are unchanged. A node whose lanes are all leaves keeps its empty
//! lanes (leaves are not opened), so there are 0.25–0.35 wide nodes per
//! triangle (against 1.1–1.5 binary
//! nodes with the SAH's small leaves): 128 bytes each, 33–45 bytes per
//! triangle (measured on a random soup and a smooth plate). Built in
//! O(nodes), no allocation beyond the node array; depth at most the binary
//! depth. Built on the first [`Bvh::closest_wide`] call, so trees that
//! never answer one (the pipeline's) do not pay for it.
//!
//! **Rounding.** Boxes are stored relative to the root box's centre and
//! scaled by a power of two that maps the root box into [-1, 1] (exact in
//! f64), then converted to f32 and moved one f32 step outward, so each
//! stored box contains its f64 box. A query point is mapped the same way,
//! clamped to ±2⁶¹ (beyond the box, clamping only moves it nearer) and
//! turned into an f32 interval `[lo, hi]` that contains it. The lane
//! distance is then the f32 distance between two intervals per axis, which
//! is at most the true distance from the point to the f64 box up to the
//! f32 rounding of three subtractions, squares and sums (a relative
//! 2⁻²² plus an absolute 2⁻¹⁴⁹ for gradual underflow); the bound it is
//! compared with is raised by more than that. So a box is pruned only
//! where the binary tree's f64 test would prune it too: the search visits
//! a superset of what is needed, and returns the binary search's answer
//! bit for bit (ties to the lowest triangle index: the answer depends on
//! the point alone, as [`Bvh::closest`] says).
//!
//! **Cost.** The same branch and bound as the binary descent (nearest child
//! first, the rest stacked with their distances and dropped when the bound
//! passes them), with about a third as many node visits, four box tests
//! each. Empty lanes hold an inverted infinite box whose distance is
//! infinite, above any bound (bounds are clamped to `f32::MAX`).

use super::bvh::{Bvh, ClosestHit, Corners, Node, MAX_DEPTH};
use crate::geometry::Aabb;
use arrayvec::ArrayVec;

/// Children per wide node.
const WIDTH: usize = 4;
/// A lane's `count` for a child that is a wide node (a leaf's count is > 0).
const INNER: u32 = 0;
/// Largest magnitude of a mapped query coordinate (the root box maps into
/// [-1, 1]): squares of three such distances stay finite in f32.
const CLAMP: f64 = (1u64 << 61) as f64;

/// One wide node: per axis, the lanes' lower and upper bounds (f32, rounded
/// outward), and per lane the child (a wide node index, or a leaf's first
/// primitive slot) and the leaf's primitive count ([`INNER`] for a node).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct WideNode {
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    child: [u32; WIDTH],
    count: [u32; WIDTH],
}

/// The wide tree of a [`Bvh`] (see the module doc). Empty for an empty tree.
#[derive(Debug, Clone, Default)]
pub(crate) struct WideBvh {
    nodes: Vec<WideNode>,
    /// Centre of the root box: stored boxes are relative to it.
    origin: [f64; 3],
    /// Power of two mapping the root box into [-1, 1].
    inv_scale: f64,
    /// `inv_scale²`: maps squared distances (exact, a power of two).
    inv_scale2: f64,
}

/// `max(a, b)` as a compare and select, which vectorizes to one instruction
/// (inputs are never NaN here).
#[inline(always)]
fn fmax(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

impl WideNode {
    const EMPTY: WideNode = WideNode {
        lo: [[f32::INFINITY; WIDTH]; 3],
        hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [u32::MAX; WIDTH],
        count: [INNER; WIDTH],
    };

    /// Lower bounds of the squared distances from the point in the interval
    /// box `[lo, hi]` to the four lanes' boxes (infinite for empty lanes).
    #[inline(always)]
    fn distances(&self, lo: &[f32; 3], hi: &[f32; 3]) -> [f32; WIDTH] {
        let mut d = [0.0f32; WIDTH];
        for k in 0..3 {
            for (i, di) in d.iter_mut().enumerate() {
                let g = fmax(fmax(self.lo[k][i] - hi[k], lo[k] - self.hi[k][i]), 0.0);
                *di += g * g;
            }
        }
        d
    }
}

/// The largest power of two not above `x` (a positive, finite f64 ≥ 2⁻¹⁰⁰⁰).
fn pow2_floor(x: f64) -> f64 {
    f64::from_bits(x.to_bits() & 0x7ff0_0000_0000_0000)
}

/// The binary nodes behind the lanes of the wide node made for binary node
/// `bi`: `bi` itself for a leaf; else its two children, then repeatedly the
/// inner lane with the largest box (the first on ties) replaced by its two
/// children, until there are [`WIDTH`] lanes or only leaves. O(1).
fn lanes(nodes: &[Node], bi: usize) -> ArrayVec<usize, WIDTH> {
    let mut lanes: ArrayVec<usize, WIDTH> = ArrayVec::new();
    if nodes[bi].is_leaf() {
        lanes.push(bi);
        return lanes;
    }
    lanes.push(bi + 1);
    lanes.push(nodes[bi].start as usize);
    while lanes.len() < WIDTH {
        let open = lanes
            .iter()
            .enumerate()
            .filter(|(_, &n)| !nodes[n].is_leaf())
            .fold(None, |acc: Option<(usize, f64)>, (i, &n)| {
                let a = nodes[n].bbox.area();
                match acc {
                    Some((_, best)) if best >= a => acc,
                    _ => Some((i, a)),
                }
            });
        let Some((i, _)) = open else { break };
        let n = lanes[i];
        lanes[i] = n + 1;
        lanes.insert(i + 1, nodes[n].start as usize);
    }
    lanes
}

impl WideBvh {
    /// Collapses the binary `nodes` (root first, depth first, as [`Bvh`]
    /// stores them) into the wide tree. O(nodes).
    pub(crate) fn build(nodes: &[Node]) -> WideBvh {
        let Some(root) = nodes.first() else {
            return WideBvh::default();
        };
        let b = &root.bbox;
        let origin = b.center();
        let half = (0..3)
            .map(|k| (b.max[k] - origin[k]).max(origin[k] - b.min[k]))
            .fold(0.0f64, f64::max)
            .max(1e-290);
        // The largest power of two not above `half`, doubled: above it.
        let scale = 2.0 * pow2_floor(half);
        let inv_scale = 1.0 / scale;
        let mut wide = WideBvh {
            nodes: Vec::with_capacity(nodes.len() / 3 + 1),
            origin,
            inv_scale,
            inv_scale2: inv_scale * inv_scale,
        };
        wide.collapse(nodes, 0);
        wide
    }

    /// Bytes of heap memory held.
    pub(crate) fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<WideNode>()
    }

    /// Appends the wide node for binary node `bi` (and, after it, its wide
    /// descendants, depth first); returns its index.
    fn collapse(&mut self, nodes: &[Node], bi: usize) -> u32 {
        let lanes = lanes(nodes, bi);
        let me = self.nodes.len();
        self.nodes.push(WideNode::EMPTY);
        for (i, &n) in lanes.iter().enumerate() {
            let (lo, hi) = self.map_box(&nodes[n].bbox);
            let (child, count) = if nodes[n].is_leaf() {
                (nodes[n].start, nodes[n].count)
            } else {
                (self.collapse(nodes, n), INNER)
            };
            let w = &mut self.nodes[me];
            for k in 0..3 {
                w.lo[k][i] = lo[k];
                w.hi[k][i] = hi[k];
            }
            w.child[i] = child;
            w.count[i] = count;
        }
        me as u32
    }

    /// `b` mapped and rounded outward to f32.
    fn map_box(&self, b: &Aabb) -> ([f32; 3], [f32; 3]) {
        let lo = std::array::from_fn(|k| {
            (((b.min[k] - self.origin[k]) * self.inv_scale) as f32).next_down()
        });
        let hi = std::array::from_fn(|k| {
            (((b.max[k] - self.origin[k]) * self.inv_scale) as f32).next_up()
        });
        (lo, hi)
    }

    /// `p` mapped, clamped and turned into an f32 interval containing it.
    #[inline(always)]
    fn map_point(&self, p: &[f64; 3]) -> ([f32; 3], [f32; 3]) {
        let m: [f32; 3] = std::array::from_fn(|k| {
            ((p[k] - self.origin[k]) * self.inv_scale).clamp(-CLAMP, CLAMP) as f32
        });
        (m.map(f32::next_down), m.map(f32::next_up))
    }

    /// The f64 pruning bound `limit` (squared) mapped to an f32 bound that
    /// every lane distance computed for a box within `limit` passes.
    #[inline(always)]
    fn bound(&self, limit: f64) -> f32 {
        let l = (limit * self.inv_scale2 * (1.0 + 1e-6)).min(f32::MAX as f64) as f32;
        (l.next_up() + f32::MIN_POSITIVE).min(f32::MAX)
    }
}

/// A stacked lane: the child, its leaf count ([`INNER`] for a node) and its
/// distance bound.
type Entry = (u32, u32, f32);

impl Bvh {
    /// The branch and bound of [`Bvh::closest`] on the wide tree: from the
    /// bound `bound2` (squared), seeded by `hint`, among the triangles
    /// `keep` accepts, the corners of each primitive slot read from
    /// `corners`. The same answer as the binary search, bit for bit.
    pub(super) fn search_wide(
        &self,
        p: [f64; 3],
        hint: Option<u32>,
        bound2: f64,
        keep: impl Fn(u32) -> bool,
        corners: &(impl Corners + ?Sized),
    ) -> Option<ClosestHit> {
        let wide = self.wide();
        if wide.nodes.is_empty() {
            return None;
        }
        let mut best = self.seed(p, hint, bound2, &keep, corners);
        let (lo, hi) = wide.map_point(&p);
        let mut bound = wide.bound(best.limit);
        // At most three entries per level: the depth bound keeps it in capacity.
        let mut stack: ArrayVec<Entry, { 3 * MAX_DEPTH + 1 }> = ArrayVec::new();
        let mut node = 0usize;
        loop {
            let w = &wide.nodes[node];
            let d = w.distances(&lo, &hi);
            // Lanes within the bound, nearest first: keys (distance bits,
            // which order as the non-negative distances do, then the lane)
            // through a 4-input sorting network; lanes out of bound last.
            let mut key: [u64; WIDTH] = std::array::from_fn(|i| {
                if d[i] <= bound {
                    ((d[i].to_bits() as u64) << 2) | i as u64
                } else {
                    u64::MAX
                }
            });
            let within = key.iter().filter(|&&k| k != u64::MAX).count();
            for (a, b) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
                let (x, y) = (key[a].min(key[b]), key[a].max(key[b]));
                key[a] = x;
                key[b] = y;
            }
            let lane = |k: u64| {
                let i = (k & 3) as usize;
                (w.child[i], w.count[i], d[i])
            };
            // Farther lanes wait on the stack, the nearest goes on.
            for &k in key[1..within.max(1)].iter().rev() {
                stack.push(lane(k));
            }
            let mut next = (within > 0).then(|| lane(key[0]));
            loop {
                match next {
                    Some((child, INNER, _)) => {
                        node = child as usize;
                        break;
                    }
                    Some((start, count, _)) => {
                        self.scan_slots(
                            start as usize,
                            count as usize,
                            &p,
                            &mut best,
                            &keep,
                            corners,
                        );
                        bound = wide.bound(best.limit);
                    }
                    None => {}
                }
                // Pop the next lane still within the bound.
                next = None;
                while let Some(e) = stack.pop() {
                    if e.2 <= bound {
                        next = Some(e);
                        break;
                    }
                }
                if next.is_none() {
                    return best.hit();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::triangle_soup;
    use rand::{Rng, SeedableRng};

    /// Every wide lane's f32 box holds its binary node's f64 box, and every
    /// primitive slot is in exactly one leaf lane (walking both trees).
    fn lanes_hold_their_binary_boxes(bvh: &Bvh) {
        // Every primitive slot is in exactly one leaf lane.
        let mut covered = vec![0u32; bvh.prim_triangle.len()];
        let w = bvh.wide();
        let mut stack = vec![(0usize, 0usize)];
        while let Some((wi, bi)) = stack.pop() {
            let lanes = lanes(&bvh.nodes, bi);
            let node = &w.nodes[wi];
            for i in 0..WIDTH {
                let Some(&bn) = lanes.get(i) else {
                    assert_eq!(node.child[i], u32::MAX, "empty lane");
                    assert!(node.lo[0][i] > node.hi[0][i]);
                    continue;
                };
                let b = &bvh.nodes[bn].bbox;
                for k in 0..3 {
                    // The f32 box, mapped back exactly, holds the f64 box.
                    let lo = node.lo[k][i] as f64 / w.inv_scale + w.origin[k];
                    let hi = node.hi[k][i] as f64 / w.inv_scale + w.origin[k];
                    assert!(
                        lo <= b.min[k] && b.max[k] <= hi,
                        "lane box {k}: {lo} {hi} {b:?}"
                    );
                }
                if bvh.nodes[bn].is_leaf() {
                    assert_eq!(
                        (node.child[i], node.count[i]),
                        (bvh.nodes[bn].start, bvh.nodes[bn].count)
                    );
                    let s = node.child[i] as usize;
                    for c in &mut covered[s..s + node.count[i] as usize] {
                        *c += 1;
                    }
                } else {
                    assert_eq!(node.count[i], INNER);
                    stack.push((node.child[i] as usize, bn));
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1), "every slot once");
    }

    /// The wide search against the binary one, bit for bit, plain, hinted
    /// and filtered, at points near and far from the soup `(v, t)`.
    fn agrees_with_the_binary_search(v: &[[f64; 3]], t: &[[u32; 3]], seed: u64) {
        let bvh = Bvh::build(v, t);
        lanes_hold_their_binary_boxes(&bvh);
        let b = &bvh.nodes[0].bbox;
        let d = b.diagonal();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let corners = &bvh.prim_corners[..];
        for i in 0..600 {
            // Near the surface, in the box, and far outside it.
            let p: [f64; 3] = match i % 3 {
                0 => {
                    let c = v[rng.gen_range(0..v.len())];
                    c.map(|x| x + 0.01 * d * rng.gen_range(-1.0..1.0))
                }
                1 => std::array::from_fn(|k| rng.gen_range(b.min[k]..=b.max[k])),
                _ => std::array::from_fn(|k| b.center()[k] + d * rng.gen_range(-1e3..1e3)),
            };
            let hint = rng.gen_bool(0.5).then(|| rng.gen_range(0..t.len() as u32));
            let keep = |tri: u32| tri % 3 != 1;
            let binary = bvh.closest(p, hint);
            assert_eq!(bvh.closest_wide(p, hint), binary, "at {p:?}");
            assert_eq!(
                bvh.search_wide(p, hint, f64::INFINITY, keep, corners),
                bvh.closest_filtered(p, hint, keep)
            );
            let r = binary.unwrap().closest.dist2.sqrt() * rng.gen_range(0.5..1.5);
            assert_eq!(
                bvh.search_wide(p, None, r * r, keep, corners),
                bvh.closest_filtered_within(p, r, keep)
            );
        }
    }

    #[test]
    fn the_wide_search_gives_the_binary_answers_at_any_scale_and_offset() {
        let (v, t) = triangle_soup(3000, 11);
        agrees_with_the_binary_search(&v, &t, 1);
        // Far from the origin (f32 could not tell the triangles apart
        // without the shift to the root box's centre), tiny, and huge.
        for (scale, shift) in [(1.0, 1e9), (1e-200, 0.0), (1e140, 0.0), (1e-6, -3e4)] {
            let w: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x * scale + shift)).collect();
            agrees_with_the_binary_search(&w, &t, 2);
        }
    }

    #[test]
    fn coincident_flat_and_single_triangle_trees() {
        // A thousand copies of one triangle (ties to the lowest index) and a
        // flat plate (a box of zero thickness).
        let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        agrees_with_the_binary_search(&v, &[[0, 1, 2]; 1000], 3);
        agrees_with_the_binary_search(&v, &[[0, 1, 2]], 4);
        let (v, t) = crate::test_shapes::unit_square(40, |_, _| 0.0);
        agrees_with_the_binary_search(&v, &t, 5);
        let empty = Bvh::build(&v, &[]);
        assert!(empty.closest_wide([0.0; 3], None).is_none());
        assert_eq!(empty.wide().memory_bytes(), 0);
    }

    #[test]
    fn mapped_points_and_bounds_are_conservative() {
        let (v, t) = triangle_soup(100, 6);
        let bvh = Bvh::build(&v, &t);
        let w = bvh.wide();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..10_000 {
            let p: [f64; 3] = std::array::from_fn(|_| {
                rng.gen_range(-2.0..2.0) * 10f64.powi(rng.gen_range(-30..30))
            });
            let (lo, hi) = w.map_point(&p);
            for k in 0..3 {
                let m = (p[k] - w.origin[k]) * w.inv_scale;
                assert!(
                    (lo[k] as f64) <= m.clamp(-CLAMP, CLAMP)
                        && m.clamp(-CLAMP, CLAMP) <= hi[k] as f64
                );
            }
            let limit = rng.gen_range(0.0..2.0) * 10f64.powi(rng.gen_range(-300..300));
            assert!(w.bound(limit) as f64 >= (limit * w.inv_scale2).min(f32::MAX as f64));
        }
        assert_eq!(w.bound(f64::INFINITY), f32::MAX);
    }
}
