//! Local operations: edge split, half-edge collapse, edge flip, and their
//! topological validity checks. Each is O(valence). None checks geometry or
//! flags; the caller decides which edges may change.

use super::{HalfedgeMesh, E_FEATURE, NONE, V_FEATURE};
use crate::error::{Error, Result};

impl HalfedgeMesh {
    /// Splits edge `e` at the new vertex placed at `p`, joining it to the
    /// opposite corner of each incident face (one or two new faces). Returns the
    /// new vertex.
    ///
    /// Payload: the new vertex gets the mean size of the edge's ends, the hint of
    /// its first end, no origin, and [`V_FEATURE`] when `e` is a feature edge; the
    /// second half of `e` copies the edge flags and line of `e`; the edges to the
    /// opposite corners are plain; each new face copies the patch of the face it
    /// was cut from.
    pub fn split(&mut self, e: u32, p: [f64; 3]) -> u32 {
        let h0 = 2 * e;
        let o0 = 2 * e + 1;
        let va = self.to[h0 as usize];
        let v2 = self.to[o0 as usize];
        let v = self.add_vertex(p);
        let (vu, au, bu) = (v as usize, va as usize, v2 as usize);
        self.vertex_size[vu] = 0.5 * (self.vertex_size[au] + self.vertex_size[bu]);
        self.vertex_hint[vu] = self.vertex_hint[bu];
        if self.edge_flags[e as usize] & E_FEATURE != 0 {
            self.vertex_flags[vu] = V_FEATURE;
        }
        // e1: v → v2 is the second half of the old edge.
        let e1 = self.new_edge(v, v2);
        let t1 = e1 ^ 1;
        self.edge_flags[(e1 >> 1) as usize] = self.edge_flags[e as usize];
        self.edge_line[(e1 >> 1) as usize] = self.edge_line[e as usize];
        let f0 = self.hface[h0 as usize];
        let f3 = self.hface[o0 as usize];
        self.vout[vu] = h0;
        self.to[o0 as usize] = v;

        if f0 != NONE {
            let h1 = self.next[h0 as usize];
            let h2 = self.next[h1 as usize];
            let v1 = self.to[h1 as usize];
            let e0 = self.new_edge(v, v1);
            let t0 = e0 ^ 1;
            let f1 = self.new_face(self.face_patch[f0 as usize]);
            self.fhe[f0 as usize] = h0;
            self.fhe[f1 as usize] = h2;
            for h in [h1, t0, h0] {
                self.hface[h as usize] = f0;
            }
            for h in [h2, t1, e0] {
                self.hface[h as usize] = f1;
            }
            self.link(h0, h1);
            self.link(h1, t0);
            self.link(t0, h0);
            self.link(e0, h2);
            self.link(h2, t1);
            self.link(t1, e0);
        } else {
            let p0 = self.prev[h0 as usize];
            self.link(p0, t1);
            self.link(t1, h0);
        }

        if f3 != NONE {
            let o1 = self.next[o0 as usize];
            let o2 = self.next[o1 as usize];
            let v3 = self.to[o1 as usize];
            let e2 = self.new_edge(v, v3);
            let t2 = e2 ^ 1;
            let f2 = self.new_face(self.face_patch[f3 as usize]);
            self.fhe[f2 as usize] = o1;
            self.fhe[f3 as usize] = o0;
            for h in [o1, t2, e1] {
                self.hface[h as usize] = f2;
            }
            for h in [o2, o0, e2] {
                self.hface[h as usize] = f3;
            }
            self.link(e1, o1);
            self.link(o1, t2);
            self.link(t2, e1);
            self.link(o0, e2);
            self.link(e2, o2);
            self.link(o2, o0);
        } else {
            let n0 = self.next[o0 as usize];
            self.link(e1, n0);
            self.link(o0, e1);
            self.vout[vu] = e1;
        }
        if self.vout[bu] == h0 {
            self.vout[bu] = t1;
        }
        v
    }

    /// True when collapsing half-edge `h` (removing `from(h)` into `to(h)`) keeps
    /// the mesh a manifold triangle mesh: the link condition (the two 1-rings
    /// share only the apexes of the edge's faces), no face left with two
    /// boundary edges, no interior edge between two boundary vertices, and no
    /// apex left with fewer than three edges (no tetrahedron or fin collapses).
    pub fn can_collapse(&self, h: u32) -> bool {
        if self.edel[(h >> 1) as usize] {
            return false;
        }
        let o = h ^ 1;
        let v0 = self.to[o as usize];
        let v1 = self.to[h as usize];
        let mut vl = NONE;
        let mut vr = NONE;
        if self.hface[h as usize] != NONE {
            let h1 = self.next[h as usize];
            let h2 = self.next[h1 as usize];
            vl = self.to[h1 as usize];
            if self.hface[(h1 ^ 1) as usize] == NONE && self.hface[(h2 ^ 1) as usize] == NONE {
                return false;
            }
            if !self.is_boundary_vertex(vl) && self.valence(vl) <= 3 {
                return false;
            }
        }
        if self.hface[o as usize] != NONE {
            let o1 = self.next[o as usize];
            let o2 = self.next[o1 as usize];
            vr = self.to[o1 as usize];
            if self.hface[(o1 ^ 1) as usize] == NONE && self.hface[(o2 ^ 1) as usize] == NONE {
                return false;
            }
            if !self.is_boundary_vertex(vr) && self.valence(vr) <= 3 {
                return false;
            }
        }
        if vl == vr {
            return false;
        }
        if self.is_boundary_vertex(v0)
            && self.is_boundary_vertex(v1)
            && self.hface[h as usize] != NONE
            && self.hface[o as usize] != NONE
        {
            return false;
        }
        for w in self.neighbors(v0) {
            if w != v1 && w != vl && w != vr && self.find_halfedge(w, v1).is_some() {
                return false;
            }
        }
        true
    }

    /// Collapses half-edge `h`: removes `from(h)` and its edge, moves `to(h)` to
    /// `position`. The faces of the edge vanish; of the two edges of each such
    /// face that merge, the one at `to(h)` survives and takes the union of both
    /// edges' flags (and the other's line when it had none).
    ///
    /// Errors (and changes nothing) when [`HalfedgeMesh::can_collapse`] is false.
    pub fn collapse(&mut self, h: u32, position: [f64; 3]) -> Result<()> {
        if !self.can_collapse(h) {
            return Err(Error::InvalidArgument(format!(
                "half-edge {h} cannot be collapsed (link condition)"
            )));
        }
        let v1 = self.to[h as usize];
        let h1 = self.prev[h as usize];
        let o1 = self.next[(h ^ 1) as usize];
        self.remove_edge(h);
        if self.next[self.next[h1 as usize] as usize] == h1 {
            self.remove_loop(h1);
        }
        if self.next[self.next[o1 as usize] as usize] == o1 {
            self.remove_loop(o1);
        }
        self.positions[v1 as usize] = position;
        Ok(())
    }

    /// Removes the edge of `h`, merging `from(h)` into `to(h)` (faces become 2-gons).
    fn remove_edge(&mut self, h: u32) {
        let hn = self.next[h as usize];
        let hp = self.prev[h as usize];
        let o = h ^ 1;
        let on = self.next[o as usize];
        let op = self.prev[o as usize];
        let fh = self.hface[h as usize];
        let fo = self.hface[o as usize];
        let vh = self.to[h as usize];
        let vo = self.to[o as usize];
        let incoming: Vec<u32> = self.outgoing(vo).map(|x| x ^ 1).collect();
        for x in incoming {
            self.to[x as usize] = vh;
        }
        self.link(hp, hn);
        self.link(op, on);
        if fh != NONE {
            self.fhe[fh as usize] = hn;
        }
        if fo != NONE {
            self.fhe[fo as usize] = on;
        }
        if self.vout[vh as usize] == o {
            self.vout[vh as usize] = hn;
        }
        self.adjust_outgoing(vh);
        self.vout[vo as usize] = NONE;
        self.vdel[vo as usize] = true;
        self.deleted[0] += 1;
        self.edel[(h >> 1) as usize] = true;
        self.deleted[1] += 1;
    }

    /// Removes the 2-gon of `h` (`next(next(h)) == h`): the edge of `h` goes,
    /// the edge of `next(h)` takes its place.
    fn remove_loop(&mut self, h0: u32) {
        let h1 = self.next[h0 as usize];
        let o0 = h0 ^ 1;
        let o1 = h1 ^ 1;
        let v0 = self.to[h0 as usize];
        let v1 = self.to[h1 as usize];
        let fh = self.hface[h0 as usize];
        let fo = self.hface[o0 as usize];
        let (e0, e1) = ((h0 >> 1) as usize, (h1 >> 1) as usize);
        self.edge_flags[e1] |= self.edge_flags[e0];
        if self.edge_line[e1] == NONE {
            self.edge_line[e1] = self.edge_line[e0];
        }
        let no0 = self.next[o0 as usize];
        let po0 = self.prev[o0 as usize];
        self.link(h1, no0);
        self.link(po0, h1);
        self.hface[h1 as usize] = fo;
        self.vout[v0 as usize] = h1;
        self.adjust_outgoing(v0);
        self.vout[v1 as usize] = o1;
        self.adjust_outgoing(v1);
        if fo != NONE && self.fhe[fo as usize] == o0 {
            self.fhe[fo as usize] = h1;
        }
        if fh != NONE {
            self.fdel[fh as usize] = true;
            self.deleted[2] += 1;
        }
        self.edel[e0] = true;
        self.deleted[1] += 1;
    }

    /// True when edge `e` can be flipped: two faces, distinct apexes not yet
    /// joined by an edge.
    pub fn is_flip_ok(&self, e: u32) -> bool {
        if self.edel[e as usize] || self.is_boundary_edge(e) {
            return false;
        }
        let h0 = 2 * e;
        let h1 = h0 + 1;
        let c = self.to[self.next[h0 as usize] as usize];
        let d = self.to[self.next[h1 as usize] as usize];
        c != d && self.find_halfedge(c, d).is_none()
    }

    /// The apexes `[c, d]` an edge would join after a flip (`c` opposite half-edge
    /// `2e`, `d` opposite `2e + 1`); meaningless on a boundary edge.
    pub fn flip_apexes(&self, e: u32) -> [u32; 2] {
        let h0 = 2 * e;
        [
            self.to[self.next[h0 as usize] as usize],
            self.to[self.next[(h0 + 1) as usize] as usize],
        ]
    }

    /// Flips edge `e` inside its two faces, so that it joins their apexes.
    /// Errors (and changes nothing) when [`HalfedgeMesh::is_flip_ok`] is false.
    pub fn flip(&mut self, e: u32) -> Result<()> {
        if !self.is_flip_ok(e) {
            return Err(Error::InvalidArgument(format!(
                "edge {e} cannot be flipped"
            )));
        }
        let a0 = 2 * e;
        let b0 = a0 + 1;
        let a1 = self.next[a0 as usize];
        let a2 = self.next[a1 as usize];
        let b1 = self.next[b0 as usize];
        let b2 = self.next[b1 as usize];
        let va0 = self.to[a0 as usize];
        let va1 = self.to[a1 as usize];
        let vb0 = self.to[b0 as usize];
        let vb1 = self.to[b1 as usize];
        let fa = self.hface[a0 as usize];
        let fb = self.hface[b0 as usize];
        self.to[a0 as usize] = va1;
        self.to[b0 as usize] = vb1;
        self.link(a0, a2);
        self.link(a2, b1);
        self.link(b1, a0);
        self.link(b0, b2);
        self.link(b2, a1);
        self.link(a1, b0);
        self.hface[a1 as usize] = fb;
        self.hface[b1 as usize] = fa;
        self.fhe[fa as usize] = a0;
        self.fhe[fb as usize] = b0;
        if self.vout[va0 as usize] == b0 {
            self.vout[va0 as usize] = a1;
        }
        if self.vout[vb0 as usize] == a0 {
            self.vout[vb0 as usize] = b1;
        }
        Ok(())
    }
}
