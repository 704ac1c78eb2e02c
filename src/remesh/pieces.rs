//! Large bodies cut into pieces that are remeshed side by side.
//!
//! The remesher's topological passes (split, collapse, flip) are sequential
//! within a part, and the parts are the bodies of an assembly, so one large
//! body was remeshed on one thread however many the machine had. Here a body
//! whose expected output ([`expected`]: its area over that of an equilateral
//! triangle of the local target) exceeds two pieces of `piece_faces` is cut
//! into pieces that become parts of their own
//! ([`HalfedgeMesh::from_grid_cut`](crate::mesh::halfedge::HalfedgeMesh::from_grid_cut)).
//!
//! **Where it is cut.** Only along feature lines: a piece is a union of
//! whole smooth patches, found by recursive bisection of the body's patches
//! (by their area-weighted centroids, along the widest axis, at the median
//! of expected faces) until a piece holds at most `piece_faces` or one
//! patch. A cut edge is locked (never split, collapsed or flipped, its
//! vertices never moved) after it has been cut to its target length
//! (`locked::presplit`), so it must already be a fair mesh edge: a crease
//! the remesher keeps anyway, and not shorter than [`MIN_CUT_RATIO`] of its
//! target (a triangle on a base of a fifth of its two other sides has an
//! 11.5° apex, above the 10° a collapse may not go below, the remesher's
//! `sliver_angle_deg`), with the faces on both sides at least that high over
//! it and neither in a patch narrower than [`NARROW_RATIO`] targets. Two
//! pieces that meet along any other edge are merged again, so a body whose
//! creases are all finely tessellated stays whole;
//! then every piece below [`MIN_PIECE_SHARE`] of `piece_faces` is merged
//! into its smallest neighbour, so a body whose area lies in one large
//! patch ringed by small ones stays whole too. Pieces that meet at a
//! vertex where the cut is not a simple seam (on a boundary or a
//! non-manifold edge, or with a piece coming back around the vertex) are
//! merged as well, before and after each of those merges.
//!
//! **Ties.** The pieces depend on the input and the targets alone (stable
//! sorts, ties by patch index), not on the thread count, so the dense grid
//! is the same bits for any number of threads. A cut changes the result
//! against remeshing the body whole: its crease vertices stay where the
//! input and the pre-split put them instead of sliding along the line.
//!
//! **Seams.** A cut crease is pre-split like the edges where bodies touch,
//! graded by the targets along it (`locked::presplit`). An earlier
//! pre-split cut each edge evenly to its midpoint's target; on
//! trimesh_fm1_satellite that left locked pieces several times the target
//! at one end, free vertices split and projected exactly onto them, and
//! flat triangles that no flip or collapse may undo across a locked edge.
//! Graded, the satellite's five pieces leave none. The remesher keeps a
//! safety net all the same: a cut whose output drops zero-area triangles
//! or changes the number of bodies is undone by remeshing whole.
//!
//! **Default.** On, with pieces of [`DEFAULT_PIECE_FACES`] (infinite
//! `RemeshParams::piece_faces` never cuts).
//!
//! Cost: O(F + P log² P) for F input faces and P patches, plus O(F) per
//! merge of a small piece (a few per cut body).

use crate::geometry::{cross, norm, sub};
use crate::mesh::topology::{find as root, union};
use crate::mesh::{Features, Grid};
use rayon::prelude::*;

/// The default `RemeshParams::piece_faces`: a body expected to make more
/// than twice this many triangles is cut. A piece's seam pins its crease
/// vertices: a square piece of N triangles has a side of about √(N/2)
/// edges, so at 50,000 about 1.3 % of its triangles touch the seam, and a
/// smaller piece pins a larger share. A body below two pieces is remeshed
/// in seconds on one thread (trimesh_featuretype, 121k triangles: 7.3 s
/// here), so smaller pieces would buy little time for more seam. The
/// value is a count of output triangles, so it means the same at any
/// scale of model or target.
pub const DEFAULT_PIECE_FACES: f64 = 50_000.0;

/// A cut edge must be at least this fraction of its target length (see the
/// module doc).
pub const MIN_CUT_RATIO: f64 = 0.2;

/// No cut borders a patch narrower than this many target lengths (its width
/// being twice its area over its perimeter), a strip of fewer than about two
/// rows of triangles: there a free vertex has no room to keep off the locked
/// crease. A margin: it came before the graded pre-split (see the module
/// doc's *Seams*) and took the satellite's zero-area triangles of the even
/// pre-split from 350 to 140; the graded pre-split takes them to none.
pub const NARROW_RATIO: f64 = 2.0;

/// A piece expected to make less than this share of `piece_faces` is merged
/// into a neighbour: its seam would cost more than its thread saves.
pub const MIN_PIECE_SHARE: f64 = 0.25;

/// How many equilateral triangles of side `l` cover `area`:
/// `area / (√3/4 · l²)`; 0 when that is not finite (no target).
pub fn expected(area: f64, l: f64) -> f64 {
    let n = 4.0 / 3f64.sqrt() * area / (l * l);
    if n.is_finite() {
        n
    } else {
        0.0
    }
}

/// A patch's weight (expected faces) and area-weighted centroid.
#[derive(Clone, Copy, Default)]
struct Patch {
    weight: f64,
    area: f64,
    moment: [f64; 3],
}

impl Patch {
    fn centroid(&self) -> [f64; 3] {
        if self.area > 0.0 {
            self.moment.map(|m| m / self.area)
        } else {
            [0.0; 3]
        }
    }
}

/// Splits `list` (patch indices) into pieces of at most `limit` expected
/// faces or one patch each, appending them to `out`.
fn bisect(list: &mut [u32], patches: &[Patch], limit: f64, out: &mut Vec<Vec<u32>>) {
    let weight: f64 = list.iter().map(|&p| patches[p as usize].weight).sum();
    if weight <= limit || list.len() < 2 {
        out.push(list.to_vec());
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &p in list.iter() {
        let c = patches[p as usize].centroid();
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
        .unwrap_or(0);
    list.sort_by(|&a, &b| {
        let (ca, cb) = (
            patches[a as usize].centroid()[axis],
            patches[b as usize].centroid()[axis],
        );
        ca.total_cmp(&cb).then(a.cmp(&b))
    });
    // The first index where the running weight reaches half, kept inside so
    // both halves hold a patch.
    let mut run = 0.0;
    let mut at = list.len() - 1;
    for (i, &p) in list.iter().enumerate() {
        run += patches[p as usize].weight;
        if run >= 0.5 * weight {
            at = i + 1;
            break;
        }
    }
    let at = at.clamp(1, list.len() - 1);
    let (a, b) = list.split_at_mut(at);
    bisect(a, patches, limit, out);
    bisect(b, patches, limit, out);
}

/// Merges every set of pieces that meet at a vertex where a cut would not
/// be a simple seam: a vertex on a boundary or non-manifold edge, or one
/// around which a piece comes back (more cut edges than pieces: A, B, A, B),
/// whose copies would then leave one piece with two fans (on sliver-ridden
/// input this made coincident, unmerged vertices). Returns whether anything
/// merged. O(F).
fn untangle(
    topo: &crate::mesh::Topology,
    piece: &[u32],
    parent: &mut [u32],
    weight: &mut [f64],
) -> bool {
    let mut changed = false;
    let mut roots: Vec<u32> = Vec::new();
    let mut edges: Vec<u32> = Vec::new();
    for v in 0..topo.vertex_face_offsets.len().saturating_sub(1) {
        let faces = topo.faces_of_vertex(v);
        roots.clear();
        roots.extend(faces.iter().map(|&f| root(parent, piece[f as usize])));
        roots.sort_unstable();
        roots.dedup();
        if roots.len() < 2 {
            continue;
        }
        edges.clear();
        for &f in faces {
            for &e in &topo.face_edges[f as usize] {
                if topo.edges[e as usize].contains(&(v as u32)) {
                    edges.push(e);
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let mut cuts = 0;
        let mut simple = true;
        for &e in &edges {
            let ef = topo.faces_of_edge(e as usize);
            if ef.len() != 2 {
                simple = false;
            } else if root(parent, piece[ef[0] as usize]) != root(parent, piece[ef[1] as usize]) {
                cuts += 1;
            }
        }
        if simple && cuts <= roots.len() {
            continue;
        }
        // The lowest root stays the root of the union.
        let lo = roots[0];
        for &r in &roots[1..] {
            union(parent, lo, r);
            weight[lo as usize] += weight[r as usize];
        }
        changed = true;
    }
    changed
}

/// How the large bodies were cut.
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// The piece of every input face, numbered by first face (a body not
    /// cut is one piece).
    pub piece: Vec<u32>,
    /// Pieces of the bodies that were cut (0 when none was).
    pub pieces: usize,
}

/// The pieces of the input (see the module doc), or `None` when no body is
/// large enough to cut (or no cut survives). `target` holds the target
/// length at each input vertex; `piece_faces` is the expected output per
/// piece (not finite or ≤ 0: never cut); `narrow` flags the patches no cut
/// may border (narrower than [`NARROW_RATIO`] targets). O(F + P log² P).
pub fn pieces(
    input: &Grid,
    features: &Features,
    narrow: &[bool],
    target: &[f64],
    piece_faces: f64,
) -> Option<Cut> {
    if !(piece_faces.is_finite() && piece_faces > 0.0) {
        return None;
    }
    let (v, tris) = (input.vertices(), input.triangles());
    let topo = input.topology();
    let per_face: Vec<(f64, f64, [f64; 3])> = tris
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            let area = 0.5 * norm(cross(sub(b, a), sub(c, a)));
            let l = t.iter().map(|&i| target[i as usize]).sum::<f64>() / 3.0;
            let m = [0, 1, 2].map(|k| area * (a[k] + b[k] + c[k]) / 3.0);
            (expected(area, l), area, m)
        })
        .collect();
    let np = features.patch_count as usize;
    let mut patches = vec![Patch::default(); np];
    let mut patch_body = vec![u32::MAX; np];
    let mut bodies = vec![0.0f64; topo.body_count as usize];
    for (f, &(w, area, m)) in per_face.iter().enumerate() {
        let p = features.face_patch[f] as usize;
        let q = &mut patches[p];
        q.weight += w;
        q.area += area;
        for k in 0..3 {
            q.moment[k] += m[k];
        }
        let b = topo.face_body[f];
        patch_body[p] = patch_body[p].min(b);
        bodies[b as usize] += w;
    }
    // A patch lies in one body (patches grow across manifold edges only),
    // so the pieces of a body are unions of its patches.
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); bodies.len()];
    for (p, &b) in patch_body.iter().enumerate() {
        if b != u32::MAX && bodies[b as usize] > 2.0 * piece_faces {
            members[b as usize].push(p as u32);
        }
    }
    let mut piece_of_patch = vec![u32::MAX; np];
    let mut count = 0u32;
    for list in members.iter_mut().filter(|l| l.len() > 1) {
        let mut out = Vec::new();
        bisect(list, &patches, piece_faces, &mut out);
        for piece in out {
            for p in piece {
                piece_of_patch[p as usize] = count;
            }
            count += 1;
        }
    }
    if count == 0 {
        return None;
    }
    // Every uncut body is one piece of its own.
    let mut piece: Vec<u32> = (0..tris.len())
        .map(|f| match piece_of_patch[features.face_patch[f] as usize] {
            u32::MAX => count + topo.face_body[f],
            p => p,
        })
        .collect();
    // Merge pieces across every edge too poor to be a cut.
    let mut parent: Vec<u32> = (0..count + topo.body_count).collect();
    for (e, ev) in topo.edges.iter().enumerate() {
        let ef = topo.faces_of_edge(e);
        if ef.len() != 2 {
            continue;
        }
        let (a, b) = (piece[ef[0] as usize], piece[ef[1] as usize]);
        if a == b {
            continue;
        }
        let [i, j] = ev.map(|x| x as usize);
        let len = norm(sub(v[i], v[j]));
        let least = MIN_CUT_RATIO * target[i].min(target[j]);
        // The faces across the cut are not needles along it: their
        // heights over it (twice the area over the length) pass the same
        // bound, or the pre-split fans them into slivers that no flip may
        // fix across a locked edge; nor does a cut border a narrow strip
        // ([`NARROW_RATIO`]).
        let height = |f: u32| 2.0 * per_face[f as usize].1 / len;
        let narrow_face =
            |f: u32| narrow.get(features.face_patch[f as usize] as usize) == Some(&true);
        let good = features.is_feature(e)
            && !narrow_face(ef[0])
            && !narrow_face(ef[1])
            && len >= least
            && height(ef[0]) >= least
            && height(ef[1]) >= least;
        if !good {
            union(&mut parent, a, b);
        }
    }
    // A piece below a quarter of `piece_faces` is not worth its seam: merge
    // it into its smallest neighbour, smallest first, until none is left
    // (a body whose weight sits in one patch, with small ones around it,
    // stays whole).
    let mut weight = vec![0.0f64; parent.len()];
    for (f, &p) in piece.iter().enumerate() {
        weight[root(&mut parent, p) as usize] += per_face[f].0;
    }
    let mut cuts: Vec<(u32, u32)> = Vec::new();
    for e in 0..topo.edges.len() {
        let ef = topo.faces_of_edge(e);
        if ef.len() == 2 {
            let (a, b) = (piece[ef[0] as usize], piece[ef[1] as usize]);
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                cuts.push((ra.min(rb), ra.max(rb)));
            }
        }
    }
    cuts.sort_unstable();
    cuts.dedup();
    loop {
        while untangle(topo, &piece, &mut parent, &mut weight) {}
        // Roots may have merged since the list was made.
        for c in cuts.iter_mut() {
            let (a, b) = (root(&mut parent, c.0), root(&mut parent, c.1));
            *c = (a.min(b), a.max(b));
        }
        cuts.retain(|c| c.0 != c.1);
        let small = cuts
            .iter()
            .flat_map(|&(a, b)| [a, b])
            .filter(|&r| weight[r as usize] < MIN_PIECE_SHARE * piece_faces)
            .min_by(|&a, &b| {
                weight[a as usize]
                    .total_cmp(&weight[b as usize])
                    .then(a.cmp(&b))
            });
        let Some(r) = small else {
            break;
        };
        let other = cuts
            .iter()
            .filter_map(|&(a, b)| match (a == r, b == r) {
                (true, _) => Some(b),
                (_, true) => Some(a),
                _ => None,
            })
            .min_by(|&a, &b| {
                weight[a as usize]
                    .total_cmp(&weight[b as usize])
                    .then(a.cmp(&b))
            });
        let Some(other) = other else {
            break;
        };
        let (lo, hi) = (r.min(other), r.max(other));
        union(&mut parent, lo, hi);
        weight[lo as usize] += weight[hi as usize];
    }
    // Number by first face; count the pieces of each body.
    let mut number = vec![u32::MAX; parent.len()];
    let mut per_body = vec![0usize; topo.body_count as usize];
    let mut next = 0u32;
    for (f, p) in piece.iter_mut().enumerate() {
        let r = root(&mut parent, *p) as usize;
        if number[r] == u32::MAX {
            number[r] = next;
            next += 1;
            per_body[topo.face_body[f] as usize] += 1;
        }
        *p = number[r];
    }
    let pieces: usize = per_body.iter().filter(|&&n| n > 1).sum();
    (pieces > 0).then_some(Cut { piece, pieces })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::box_grid;

    #[test]
    fn a_large_box_is_cut_along_its_creases_only() {
        let g = box_grid(4);
        let f = Features::detect(&g, 30.0);
        assert_eq!(f.patch_count, 6);
        let target = vec![0.01; g.vertices().len()];
        // 6 faces of ~11,547 expected triangles each: pieces of two faces.
        let cut = pieces(&g, &f, &[], &target, 25_000.0).expect("cut");
        assert!(cut.pieces >= 3, "{} pieces", cut.pieces);
        let p = &cut.piece;
        assert_eq!(*p.iter().max().unwrap() as usize + 1, cut.pieces);
        // Every face of one patch is in one piece.
        for (a, b) in f.face_patch.iter().zip(p) {
            for (c, d) in f.face_patch.iter().zip(p) {
                if a == c {
                    assert_eq!(b, d);
                }
            }
        }
        // Deterministic.
        assert_eq!(pieces(&g, &f, &[], &target, 25_000.0), Some(cut));
    }

    #[test]
    fn small_or_finely_creased_bodies_stay_whole() {
        let g = box_grid(4);
        let f = Features::detect(&g, 30.0);
        let target = vec![0.01; g.vertices().len()];
        assert_eq!(pieces(&g, &f, &[], &target, 1e6), None);
        assert_eq!(pieces(&g, &f, &[], &target, f64::INFINITY), None);
        // Crease edges of 0.25 against a target of 2.0: too short to cut.
        let coarse = vec![2.0; g.vertices().len()];
        assert_eq!(pieces(&g, &f, &[], &coarse, 0.1), None);
    }
}
