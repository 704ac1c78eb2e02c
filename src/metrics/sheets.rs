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

/// Do unnormalised normals `n` and `m` face each other?
fn facing_back(n: [f64; 3], m: [f64; 3]) -> bool {
    dot(n, m) < FACING_BACK * norm(n) * norm(m)
}

impl<'a> Sheets<'a> {
    /// Matches the bodies (O(F_c log F_r), parallel, deterministic: votes are
    /// counted per body and ties go to the lower body number).
    pub(crate) fn new(reference: &'a Grid, candidate: &'a Grid, contact: f64) -> Sheets<'a> {
        let ct = candidate.topology();
        let rt = reference.topology();
        let v = candidate.vertices();
        let votes: Vec<u32> = candidate
            .triangles()
            .par_iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|i| v[i as usize]);
                let m = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
                reference
                    .bvh()
                    .closest(m, None)
                    .map_or(0, |h| rt.face_body[h.triangle as usize])
            })
            .collect();
        let nb = rt.body_count as usize;
        let mut count = vec![vec![0u32; nb.max(1)]; ct.body_count as usize];
        for (f, &b) in votes.iter().enumerate() {
            count[ct.face_body[f] as usize][b as usize] += 1;
        }
        let body_map = count
            .iter()
            .map(|c| {
                let mut best = 0;
                for (i, &n) in c.iter().enumerate() {
                    if n > c[best] {
                        best = i;
                    }
                }
                best as u32
            })
            .collect();
        Sheets {
            reference,
            candidate,
            body_map,
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
