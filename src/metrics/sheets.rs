//! Wrong-sheet detection: does a query on the candidate grid, made at a point
//! of the reference surface, land on the sheet the point lies on?
//!
//! A sample `p` on reference triangle `f` (body `B`, normal `n`) lands on the
//! candidate's closest point `q`. The landing is **right** when some candidate
//! triangle containing `q` (one, or all those sharing `q`'s edge or vertex: at
//! a tie the query may return any of them) belongs to the body that `B`
//! became and does not face back, `n̂·n̂' ≥ −0.2` (the proximity sizes'
//! threshold: a face met across a sharp edge at about 90° is a neighbour, not
//! an opposite wall). Otherwise it is **wrong**: the query crossed a thin
//! wall, a slot or the gap to another body, where the sizes of the two sides
//! need not agree.
//!
//! Samples at a contact are left out: when the reference itself has another
//! sheet (another body, or a face facing back) within the contact
//! distance of `p`, the point lies on both, and which sheet it reads is the
//! contact rule's business (the two sizes agree there), not a fidelity loss.
//!
//! Candidate bodies are matched to reference bodies by a vote: every candidate
//! face's centroid votes for the body of its closest reference face.

use crate::geometry::{cross, dot, norm, sub};
use crate::mesh::Grid;
use crate::sizing::proximity::FACING_BACK;
use rayon::prelude::*;

/// What wrong-sheet detection needs, computed once per evaluation.
pub(crate) struct Sheets<'a> {
    reference: &'a Grid,
    candidate: &'a Grid,
    /// Reference body of each candidate body.
    body_map: Vec<u32>,
    /// Distance below which two sheets are in contact.
    contact: f64,
}

/// Unnormalised normal of triangle `t` of `g`.
fn normal(g: &Grid, t: u32) -> [f64; 3] {
    let [a, b, c] = g.triangles()[t as usize].map(|i| g.vertices()[i as usize]);
    cross(sub(b, a), sub(c, a))
}

/// The reference body of each candidate body: every candidate face's centroid
/// votes, with its area, for the body of its closest reference face. A face
/// lying at a contact (another reference body within the contact gap of its
/// centroid) votes only when its body has no other votes: the bottom of a
/// block on a plate is as close to the plate as to the block, and a finely
/// graded contact face must not outvote a coarse body. O(F_c log F_r),
/// parallel, deterministic (votes are summed per body in face order and ties
/// go to the lower body number).
pub(crate) fn body_map(reference: &Grid, candidate: &Grid) -> Vec<u32> {
    let ct = candidate.topology();
    let rt = reference.topology();
    let v = candidate.vertices();
    let gap = reference.contact_gap();
    let several = rt.body_count > 1;
    // (reference body, area, at a contact) per candidate face.
    let votes: Vec<(u32, f64, bool)> = candidate
        .triangles()
        .par_iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| v[i as usize]);
            let m = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
            let area = 0.5 * norm(cross(sub(b, a), sub(c, a)));
            let Some(hit) = reference.bvh().closest(m, None) else {
                return (0, area, false);
            };
            let body = rt.face_body[hit.triangle as usize];
            let shared = several
                && reference
                    .bvh()
                    .closest_filtered_within(m, hit.closest.dist2.sqrt() + gap, |t| {
                        rt.face_body[t as usize] != body
                    })
                    .is_some();
            (body, area, shared)
        })
        .collect();
    let nb = (rt.body_count as usize).max(1);
    let mut clear = vec![vec![0.0f64; nb]; ct.body_count as usize];
    let mut shared = clear.clone();
    for (f, &(b, area, at_contact)) in votes.iter().enumerate() {
        let tally = if at_contact { &mut shared } else { &mut clear };
        // A degenerate face still counts, so a body never goes without votes.
        tally[ct.face_body[f] as usize][b as usize] += area.max(f64::MIN_POSITIVE);
    }
    clear
        .iter()
        .zip(&shared)
        .map(|(c, s)| {
            let c = if c.iter().any(|&x| x > 0.0) { c } else { s };
            let mut best = 0;
            for (i, &n) in c.iter().enumerate() {
                if n > c[best] {
                    best = i;
                }
            }
            best as u32
        })
        .collect()
}

/// Do unnormalised normals `n` and `m` face each other?
fn facing_back(n: [f64; 3], m: [f64; 3]) -> bool {
    dot(n, m) < FACING_BACK * norm(n) * norm(m)
}

impl<'a> Sheets<'a> {
    /// Matches the bodies ([`body_map`]).
    pub(crate) fn new(reference: &'a Grid, candidate: &'a Grid, contact: f64) -> Sheets<'a> {
        Sheets {
            reference,
            candidate,
            body_map: body_map(reference, candidate),
            contact,
        }
    }

    /// Is the landing of sample `p` (on reference triangle `f`) on candidate
    /// triangle `tri` at barycentric `bary` wrong? O(1) for a right landing
    /// inside a triangle; O(log F_r) more to rule out a contact.
    pub(crate) fn wrong(&self, p: [f64; 3], f: u32, tri: u32, bary: [f64; 3]) -> bool {
        let n = normal(self.reference, f);
        let body = self.reference.topology().face_body[f as usize];
        let ct = self.candidate.topology();
        let right = |t: u32| {
            self.body_map[ct.face_body[t as usize] as usize] == body
                && !facing_back(n, normal(self.candidate, t))
        };
        if right(tri) {
            return false;
        }
        // On an edge or at a vertex, any triangle sharing it is an answer too.
        let corners = self.candidate.triangles()[tri as usize];
        let on: Vec<u32> = (0..3)
            .filter(|&k| bary[k] > 0.0)
            .map(|k| corners[k])
            .collect();
        let shared: &[u32] = match on.as_slice() {
            [v] => ct.faces_of_vertex(*v as usize),
            [a, b] => ct.find_edge(*a, *b).map_or(&[], |e| ct.faces_of_edge(e)),
            _ => &[],
        };
        if shared.iter().any(|&t| right(t)) {
            return false;
        }
        // At a contact the point lies on both sheets.
        let rt = self.reference.topology();
        let at_contact = self
            .reference
            .bvh()
            .closest_filtered_within(p, self.contact, |t| {
                rt.face_body[t as usize] != body || facing_back(n, normal(self.reference, t))
            })
            .is_some();
        !at_contact
    }
}
