//! A [`Bvh`] taken apart into its *layout* — the tree shape and the order of
//! the triangles in the leaves — and put together again, so that a stored grid
//! ([`crate::io::abgs_bin`]) need not rebuild its hierarchy.
//!
//! The layout is what the build decided (the binned SAH splits, the costly
//! part); everything else is derived from it and the triangles: node boxes
//! (bottom up, the same min/max over the same corners as the build, so the
//! same boxes), leaf corner copies, the inverse permutation and the rounding
//! scale. A layout from outside is checked completely before it is used, so a
//! forged one can make queries neither unsafe, nor panic, nor wrong: the tree
//! must be the depth-first flattening the traversals assume (left child right
//! after its parent, right child where `start` says, every node reached once),
//! at most [`MAX_DEPTH`] levels deep (traversal stacks are fixed arrays), with
//! leaves that cover the primitive slots once, in order, and a permutation of
//! the triangles. Boxes are never taken from outside, so they always hold
//! their triangles.

use super::bvh::{coord_scale, Bvh, Node, MAX_DEPTH};
use crate::geometry::Aabb;

/// A hierarchy's layout: per node `[start, count]` (a leaf: first slot and
/// number of primitives, `count > 0`; an inner node: index of the right
/// child, `count == 0`), and the triangle in each primitive slot.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BvhLayout {
    /// `[start, count]` of each node, root first, depth-first.
    pub nodes: Vec<[u32; 2]>,
    /// Triangle index of each primitive slot (leaf order).
    pub prim_triangle: Vec<u32>,
}

impl Bvh {
    /// The layout of this hierarchy (a copy). O(nodes + F).
    pub fn layout(&self) -> BvhLayout {
        BvhLayout {
            nodes: self.nodes.iter().map(|n| [n.start, n.count]).collect(),
            prim_triangle: self.prim_triangle.clone(),
        }
    }

    /// Rebuilds the hierarchy over `triangles` (indices into `vertices`, which
    /// the caller has checked: in range, finite) from a `layout`, after checking
    /// that the layout is one a build could have made for this many triangles.
    /// The result equals [`Bvh::build`]'s when the layout is its layout.
    /// Errors (a message saying what is wrong) on any inconsistency.
    /// O(nodes + F), no recursion.
    pub fn from_layout(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        layout: BvhLayout,
    ) -> Result<Bvh, String> {
        let BvhLayout {
            nodes,
            prim_triangle,
        } = layout;
        let nt = triangles.len();
        if nt == 0 {
            return if nodes.is_empty() && prim_triangle.is_empty() {
                Ok(Bvh::default())
            } else {
                Err("a hierarchy over no triangles must be empty".into())
            };
        }
        if prim_triangle.len() != nt {
            return Err(format!(
                "{} primitive slots for {nt} triangles",
                prim_triangle.len()
            ));
        }
        // A binary tree with nt non-empty leaves has at most 2·nt − 1 nodes.
        if nodes.is_empty() || nodes.len() > 2 * nt - 1 {
            return Err(format!(
                "{} nodes for {nt} triangles (1 to {} possible)",
                nodes.len(),
                2 * nt - 1
            ));
        }
        let mut triangle_prim = vec![u32::MAX; nt];
        for (slot, &t) in prim_triangle.iter().enumerate() {
            match triangle_prim.get_mut(t as usize) {
                Some(p) if *p == u32::MAX => *p = slot as u32,
                Some(_) => return Err(format!("triangle {t} is in two primitive slots")),
                None => return Err(format!("primitive slot {slot} names triangle {t} of {nt}")),
            }
        }
        check_shape(&nodes, nt)?;
        let prim_corners: Vec<[[f64; 3]; 3]> = prim_triangle
            .iter()
            .map(|&t| triangles[t as usize].map(|v| vertices[v as usize]))
            .collect();
        // Boxes bottom up: children come after their parent.
        let mut built = vec![
            Node {
                bbox: Aabb::EMPTY,
                start: 0,
                count: 0,
            };
            nodes.len()
        ];
        for i in (0..nodes.len()).rev() {
            let [start, count] = nodes[i];
            let mut bbox = Aabb::EMPTY;
            if count > 0 {
                let s = start as usize;
                for c in &prim_corners[s..s + count as usize] {
                    bbox.merge(&Aabb::from_points(c));
                }
            } else {
                bbox.merge(&built[i + 1].bbox);
                bbox.merge(&built[start as usize].bbox);
            }
            built[i] = Node { bbox, start, count };
        }
        let coord_scale = coord_scale(&built[0].bbox);
        Ok(Bvh {
            wide: Default::default(),
            nodes: built,
            prim_triangle,
            prim_corners,
            triangle_prim,
            coord_scale,
        })
    }
}

/// Checks that `nodes` is a depth-first flattened binary tree whose leaves
/// cover the slots `0..nt` once, in order, at most [`MAX_DEPTH`] levels deep.
/// Walks the tree once from the root with an explicit stack: node `i`'s left
/// child must be `i + 1` and each node must be the next one in depth-first
/// order when it is reached, so every node is reached exactly once and the
/// `start` of an inner node (its right child) is where its left subtree ends.
fn check_shape(nodes: &[[u32; 2]], nt: usize) -> Result<(), String> {
    let mut next_node = 0usize;
    let mut next_slot = 0usize;
    // (node, its depth)
    let mut stack: Vec<(usize, usize)> = vec![(0, 1)];
    while let Some((i, depth)) = stack.pop() {
        if i != next_node {
            return Err(format!(
                "node {i} is reached where node {next_node} should come (not a depth-first layout)"
            ));
        }
        let Some(&[start, count]) = nodes.get(i) else {
            return Err(format!("node {i} is past the {} nodes", nodes.len()));
        };
        if depth > MAX_DEPTH {
            return Err(format!("deeper than {MAX_DEPTH} levels"));
        }
        next_node += 1;
        if count > 0 {
            if start as usize != next_slot {
                return Err(format!(
                    "leaf {i} starts at slot {start}, slot {next_slot} expected"
                ));
            }
            next_slot = next_slot
                .checked_add(count as usize)
                .filter(|&s| s <= nt)
                .ok_or_else(|| format!("leaf {i} runs past the {nt} primitive slots"))?;
        } else {
            let right = start as usize;
            if right <= i + 1 || right >= nodes.len() {
                return Err(format!("inner node {i} has its right child at {right}"));
            }
            // Right pushed first: the left subtree (i + 1) is walked first.
            stack.push((right, depth + 1));
            stack.push((i + 1, depth + 1));
        }
    }
    if next_node != nodes.len() {
        return Err(format!(
            "{} of {} nodes are not in the tree",
            nodes.len() - next_node,
            nodes.len()
        ));
    }
    if next_slot != nt {
        return Err(format!("the leaves cover {next_slot} of {nt} slots"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let z = ((i * 7 + j * 3) % 5) as f64 * 0.01;
                v.push([i as f64, j as f64, z]);
            }
        }
        let mut t = Vec::new();
        let w = (n + 1) as u32;
        for j in 0..n as u32 {
            for i in 0..n as u32 {
                let a = j * w + i;
                t.push([a, a + 1, a + w + 1]);
                t.push([a, a + w + 1, a + w]);
            }
        }
        (v, t)
    }

    fn same(a: &Bvh, b: &Bvh) {
        assert_eq!(a.nodes.len(), b.nodes.len());
        for (x, y) in a.nodes.iter().zip(&b.nodes) {
            assert_eq!((x.start, x.count), (y.start, y.count));
            assert_eq!(x.bbox, y.bbox);
        }
        assert_eq!(a.prim_triangle, b.prim_triangle);
        assert_eq!(a.triangle_prim, b.triangle_prim);
        assert_eq!(a.prim_corners, b.prim_corners);
        assert_eq!(a.coord_scale.to_bits(), b.coord_scale.to_bits());
    }

    #[test]
    fn a_layout_gives_back_the_built_tree() {
        for n in [1, 2, 5, 40] {
            let (v, t) = plate(n);
            let b = Bvh::build(&v, &t);
            same(&Bvh::from_layout(&v, &t, b.layout()).unwrap(), &b);
        }
        assert!(Bvh::from_layout(&[], &[], BvhLayout::default())
            .unwrap()
            .nodes
            .is_empty());
    }

    #[test]
    fn every_broken_layout_is_refused() {
        let (v, t) = plate(6);
        let good = Bvh::build(&v, &t).layout();
        let inner = good.nodes.iter().position(|n| n[1] == 0).unwrap();
        let leaf = good.nodes.iter().position(|n| n[1] > 0).unwrap();
        let last = good.nodes.len() - 1;
        type Edit = Box<dyn Fn(&mut BvhLayout)>;
        let cases: Vec<(&str, Edit)> = vec![
            ("no nodes", Box::new(|l| l.nodes.clear())),
            ("extra node", Box::new(|l| l.nodes.push([0, 1]))),
            (
                "slot missing",
                Box::new(|l| {
                    l.prim_triangle.pop();
                }),
            ),
            (
                "slot repeated",
                Box::new(|l| l.prim_triangle[1] = l.prim_triangle[0]),
            ),
            (
                "slot out of range",
                Box::new(|l| l.prim_triangle[0] = 1 << 30),
            ),
            (
                "right child = left",
                Box::new(move |l| l.nodes[inner][0] = inner as u32 + 1),
            ),
            (
                "right child = self",
                Box::new(move |l| l.nodes[inner][0] = inner as u32),
            ),
            (
                "right child past end",
                Box::new(move |l| l.nodes[inner][0] = u32::MAX),
            ),
            (
                "right child shifted",
                Box::new(move |l| l.nodes[inner][0] += 1),
            ),
            ("leaf shifted", Box::new(move |l| l.nodes[leaf][0] += 1)),
            ("leaf longer", Box::new(move |l| l.nodes[leaf][1] += 1)),
            ("leaf huge", Box::new(move |l| l.nodes[last][1] = u32::MAX)),
            ("leaf made inner", Box::new(move |l| l.nodes[leaf][1] = 0)),
            ("root a leaf", Box::new(|l| l.nodes[0] = [0, 1])),
        ];
        for (what, f) in cases {
            let mut l = good.clone();
            f(&mut l);
            assert!(Bvh::from_layout(&v, &t, l).is_err(), "{what}");
        }
        // Too deep: a chain of inner nodes, each with a one-triangle right leaf.
        let n = MAX_DEPTH + 1;
        let (v, t) = plate(n);
        let t = &t[..n];
        // Depth-first: an inner node, its left subtree (the chain), its right leaf.
        fn chain(nodes: &mut Vec<[u32; 2]>, first_slot: u32, n: u32) {
            if n == 1 {
                nodes.push([first_slot, 1]);
                return;
            }
            let i = nodes.len();
            nodes.push([0, 0]);
            chain(nodes, first_slot, n - 1);
            nodes[i][0] = nodes.len() as u32;
            nodes.push([first_slot + n - 1, 1]);
        }
        let mut nodes = Vec::new();
        chain(&mut nodes, 0, n as u32);
        let layout = BvhLayout {
            nodes,
            prim_triangle: (0..n as u32).collect(),
        };
        let e = Bvh::from_layout(&v, t, layout.clone()).unwrap_err();
        assert!(e.contains("deeper"), "{e}");
        // One level less is accepted (and answers like a built tree).
        let (m, t2) = (n - 1, &t[..n - 1]);
        let mut nodes = Vec::new();
        chain(&mut nodes, 0, m as u32);
        let b = Bvh::from_layout(
            &v,
            t2,
            BvhLayout {
                nodes,
                prim_triangle: (0..m as u32).collect(),
            },
        )
        .unwrap();
        assert_eq!(b.depth(), MAX_DEPTH);
        let built = Bvh::build(&v, t2);
        for p in [[0.3, 0.2, 1.0], [50.0, 0.5, -2.0], [-3.0, 0.9, 0.0]] {
            assert_eq!(b.closest(p, None), built.closest(p, None));
        }
    }
}
