//! Plain quadric-error decimation (Garland & Heckbert 1997), the baseline the
//! sizing-aware simplifier is compared with: "plain quadric decimation to the
//! same face count, with sizes re-projected".
//!
//! It follows the standard decimators (OpenMesh's `Decimater` with
//! `ModQuadric` + `ModNormalFlipping`, CGAL's `edge_collapse` with the
//! Garland–Heckbert policies):
//!
//! - **Quadrics.** Each vertex starts with the sum of the planes of its
//!   faces, each weighted by the face area. Every feature edge (boundary,
//!   sharp above [`QemParams::feature_angle_deg`], non-manifold) adds, for
//!   each of its faces, the plane through the edge perpendicular to that face,
//!   weighted by [`QemParams::boundary_weight`] × edge length², to both ends.
//!   A collapse gives the kept vertex the sum of both quadrics.
//! - **Placement.** An edge between two free vertices (on no feature) goes to
//!   the point minimising its quadric when the 3×3 system is well conditioned
//!   (solved in f64 by nalgebra's LU; the point must also lie within one edge length of the
//!   edge's midpoint), else to the cheapest of its ends and its midpoint.
//!   Otherwise one end stays where it is: a free vertex may be removed into any
//!   neighbour, a vertex on a feature line only into a neighbour along a
//!   feature edge (so the line is kept), placed at that neighbour. Corners
//!   (feature valence ≠ 2, or a line turning by more than the feature angle)
//!   and locked vertices (copies at non-manifold input vertices) never move
//!   and are never removed; locked edges are never collapsed.
//! - **Validity**, checked when a collapse is taken from the queue: the link
//!   condition ([`HalfedgeMesh::can_collapse`], which also keeps bodies apart
//!   and the topology unchanged), no face whose normal turns by more than
//!   [`QemParams::max_normal_turn_deg`] (nor flips), no degenerate face, no two
//!   feature edges merged into one, no edge made between two locked vertices.
//! - **Order.** A binary heap of edges ordered by (cost, edge id), so the
//!   result is deterministic; stale entries are skipped lazily by a version
//!   stamp per edge. After a collapse every edge touching the kept vertex's
//!   1-ring is re-evaluated (its cost or validity may have changed). An edge
//!   found invalid leaves the queue until a later collapse nearby re-inserts
//!   it. Decimation stops at [`QemParams::target_faces`] (a collapse removes two
//!   faces inside, one on a boundary, so a closed surface may end one below an
//!   odd target) or when no valid collapse remains.
//!
//! When the input carries sizes, the output gets them re-projected:
//! `h(v) = input.query_size(v)`, the interpolated size at the closest point of
//! the input, so the result is itself a valid background grid.
//!
//! Cost: O(E log E) for E input edges (each collapse re-evaluates O(valence²)
//! edges, each push or pop is O(log E)), plus O(V log F) for the size
//! re-projection. The topological work is sequential; only the size
//! re-projection is parallel (rayon), and the output does not depend on the
//! thread count.

use crate::error::{Error, Result};
use crate::geometry::{cross, dot, lerp, norm, norm2, scale, sub};
use crate::mesh::halfedge::{
    HalfedgeMesh, E_FEATURE, E_LOCKED, NONE, V_CORNER, V_FEATURE, V_LOCKED,
};
use crate::mesh::{BuildOptions, Features, Grid};
use nalgebra::{Matrix3, Vector3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

/// Parameters of [`decimate`]. `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct QemParams {
    /// Number of faces to stop at (≥ 1). Inputs with no more faces than this
    /// are returned unchanged.
    pub target_faces: usize,
    /// Dihedral angle above which an edge is a feature, degrees (30). A
    /// feature line turning by more than this at a vertex has a corner there.
    pub feature_angle_deg: f64,
    /// Largest turn of a face normal a collapse may cause, degrees (60).
    pub max_normal_turn_deg: f64,
    /// Weight of the constraint planes of feature edges relative to the face
    /// planes (1000).
    pub boundary_weight: f64,
}

impl Default for QemParams {
    fn default() -> Self {
        QemParams {
            target_faces: 1000,
            feature_angle_deg: 30.0,
            max_normal_turn_deg: 60.0,
            boundary_weight: 1000.0,
        }
    }
}

/// The result of [`decimate`].
#[derive(Debug, Clone)]
pub struct Decimated {
    /// The decimated grid, with sizes re-projected from the input when the
    /// input has sizes.
    pub grid: Grid,
    /// Edge collapses performed.
    pub collapses: usize,
    /// Total seconds spent (size re-projection included).
    pub seconds: f64,
}

/// A symmetric quadric `Q(x) = xᵀ A x + 2 bᵀ x + c`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Quadric {
    /// A as xx, xy, xz, yy, yz, zz.
    a: [f64; 6],
    b: [f64; 3],
    c: f64,
}

impl Quadric {
    /// `w · (n·x + d)²`.
    fn plane(n: [f64; 3], d: f64, w: f64) -> Quadric {
        Quadric {
            a: [
                w * n[0] * n[0],
                w * n[0] * n[1],
                w * n[0] * n[2],
                w * n[1] * n[1],
                w * n[1] * n[2],
                w * n[2] * n[2],
            ],
            b: [w * d * n[0], w * d * n[1], w * d * n[2]],
            c: w * d * d,
        }
    }

    fn add(&self, o: &Quadric) -> Quadric {
        let mut r = *self;
        for i in 0..6 {
            r.a[i] += o.a[i];
        }
        for i in 0..3 {
            r.b[i] += o.b[i];
        }
        r.c += o.c;
        r
    }

    /// Q(p), clamped at 0 (round-off can make it slightly negative).
    fn eval(&self, p: [f64; 3]) -> f64 {
        let a = &self.a;
        let [x, y, z] = p;
        let v = a[0] * x * x
            + a[3] * y * y
            + a[5] * z * z
            + 2.0 * (a[1] * x * y + a[2] * x * z + a[4] * y * z)
            + 2.0 * (self.b[0] * x + self.b[1] * y + self.b[2] * z)
            + self.c;
        v.max(0.0)
    }

    /// The minimiser `A⁻¹(−b)` when A is well conditioned: |det A| above
    /// 1e-10 of (trace/3)³ (A is positive semi-definite, so this bounds the
    /// product of its two smaller eigenvalues relative to the largest).
    fn optimum(&self) -> Option<[f64; 3]> {
        let [a00, a01, a02, a11, a12, a22] = self.a;
        let a = Matrix3::new(a00, a01, a02, a01, a11, a12, a02, a12, a22);
        let det = a.determinant();
        let tr = a.trace() / 3.0;
        if !(det.is_finite() && tr > 0.0 && det.abs() > 1e-10 * tr * tr * tr) {
            return None;
        }
        let x = a.lu().solve(&-Vector3::from(self.b))?;
        x.iter()
            .all(|t| t.is_finite())
            .then_some([x[0], x[1], x[2]])
    }
}

/// A queued edge; its collapse is the edge's current [`Plan`] when `stamp`
/// is the edge's current stamp (else the entry is stale).
#[derive(Debug, Clone, Copy)]
struct Entry {
    cost: f64,
    edge: u32,
    stamp: u32,
}

/// The best collapse of an edge: remove `from(h)` into `to(h)`, placed at `pos`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Plan {
    h: u32,
    pos: [f64; 3],
}

impl Ord for Entry {
    /// Reversed, so the [`BinaryHeap`] pops the lowest (cost, edge, stamp).
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost
            .total_cmp(&self.cost)
            .then(o.edge.cmp(&self.edge))
            .then(o.stamp.cmp(&self.stamp))
    }
}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}

/// Flatness `|ab × ac| / (longest side)²` below which a new face is degenerate.
const MIN_FLATNESS: f64 = 1e-6;

/// Decimation state: the mesh, its quadrics and the queue.
struct Decimator {
    mesh: HalfedgeMesh,
    quadric: Vec<Quadric>,
    stamp: Vec<u32>,
    /// The edge has a live (current-stamp) entry in the heap.
    queued: Vec<bool>,
    plan: Vec<Plan>,
    cost: Vec<f64>,
    touched: Vec<usize>,
    heap: BinaryHeap<Entry>,
    cos_turn: f64,
}

fn check(params: &QemParams) -> Result<()> {
    let bad = |what: &str, x: f64, range: &str| {
        Err(Error::InvalidArgument(format!(
            "{what} = {x} must be {range}"
        )))
    };
    if params.target_faces == 0 {
        return Err(Error::InvalidArgument("target_faces must be ≥ 1".into()));
    }
    let a = params.feature_angle_deg;
    if !(a.is_finite() && (0.0..=180.0).contains(&a)) {
        return bad("feature_angle_deg", a, "in [0, 180]");
    }
    let t = params.max_normal_turn_deg;
    if !(t.is_finite() && t > 0.0 && t <= 180.0) {
        return bad("max_normal_turn_deg", t, "in (0, 180]");
    }
    let w = params.boundary_weight;
    if !(w.is_finite() && w >= 0.0) {
        return bad("boundary_weight", w, "finite and ≥ 0");
    }
    Ok(())
}

/// Decimates `input` by quadric-error edge collapses down to
/// `params.target_faces` faces (or as far as valid collapses allow), keeping
/// its feature lines, boundaries, corners, bodies and topology; see the
/// module docs. Sizes, when the input has them, are re-projected from the
/// input. Errors ([`Error::InvalidArgument`]) on invalid parameters. O(E log E).
pub fn decimate(input: &Grid, params: &QemParams) -> Result<Decimated> {
    check(params)?;
    let start = Instant::now();
    let features = Features::detect(input, params.feature_angle_deg);
    let (mut mesh, _) = HalfedgeMesh::from_grid(input, Some(&features));
    crate::mesh::feature_lines::mark_corners(&mut mesh, params.feature_angle_deg);
    let quadric = initial_quadrics(&mesh, params.boundary_weight);
    let ne = mesh.n_edges();
    let mut d = Decimator {
        mesh,
        quadric,
        stamp: vec![0; ne],
        queued: vec![false; ne],
        plan: vec![
            Plan {
                h: NONE,
                pos: [0.0; 3]
            };
            ne
        ],
        cost: vec![f64::INFINITY; ne],
        touched: vec![0; ne],
        heap: BinaryHeap::with_capacity(ne),
        cos_turn: params.max_normal_turn_deg.to_radians().cos(),
    };
    let mut collapses = 0;
    if d.mesh.face_count() > params.target_faces {
        for e in 0..ne as u32 {
            d.push(e);
        }
        collapses = d.run(params.target_faces);
    }
    let grid = output(&d.mesh, input)?;
    Ok(Decimated {
        grid,
        collapses,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Area-weighted face planes plus weighted constraint planes along feature
/// edges, summed per vertex. O(V + E + F).
fn initial_quadrics(mesh: &HalfedgeMesh, weight: f64) -> Vec<Quadric> {
    let mut q = vec![Quadric::default(); mesh.n_vertices()];
    let unit_normal = |f: u32| {
        let n = mesh.face_normal2(f);
        let l = norm(n);
        (l > 0.0 && l.is_finite()).then(|| (scale(n, 1.0 / l), 0.5 * l))
    };
    for f in mesh.faces() {
        let Some((n, area)) = unit_normal(f) else {
            continue;
        };
        let vs = mesh.face_vertices(f);
        let p = mesh.positions[vs[0] as usize];
        let fq = Quadric::plane(n, -dot(n, p), area);
        for v in vs {
            q[v as usize] = q[v as usize].add(&fq);
        }
    }
    if weight > 0.0 {
        for e in mesh.edges() {
            if mesh.edge_flags[e as usize] & E_FEATURE == 0 {
                continue;
            }
            let [a, b] = mesh.edge_vertices(e);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let dir = sub(pb, pa);
            for h in [2 * e, 2 * e + 1] {
                let f = mesh.face(h);
                if f == NONE {
                    continue;
                }
                let Some((nf, _)) = unit_normal(f) else {
                    continue;
                };
                let c = cross(dir, nf);
                let l = norm(c);
                if !(l > 0.0 && l.is_finite()) {
                    continue;
                }
                let n = scale(c, 1.0 / l);
                let cq = Quadric::plane(n, -dot(n, pa), weight * norm2(dir));
                q[a as usize] = q[a as usize].add(&cq);
                q[b as usize] = q[b as usize].add(&cq);
            }
        }
    }
    q
}

impl Decimator {
    #[inline]
    fn flags(&self, v: u32) -> u8 {
        self.mesh.vertex_flags[v as usize]
    }

    /// The best collapse of edge `e` (ignoring geometric validity), if its
    /// flags allow one: half-edge, position, cost.
    fn evaluate(&self, e: u32) -> Option<(Plan, f64)> {
        let m = &self.mesh;
        let ef = m.edge_flags[e as usize];
        if m.edge_deleted(e) || ef & E_LOCKED != 0 {
            return None;
        }
        let [a, b] = m.edge_vertices(e);
        let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
        let q = self.quadric[a as usize].add(&self.quadric[b as usize]);
        let free = |v: u32| self.flags(v) & (V_FEATURE | V_CORNER | V_LOCKED) == 0;
        if free(a) && free(b) {
            let mid = lerp(pa, pb, 0.5);
            let len2 = norm2(sub(pa, pb));
            let opt = q
                .optimum()
                .filter(|&x| norm2(sub(x, mid)) <= len2)
                .map(|x| (q.eval(x), x));
            let best = opt.unwrap_or_else(|| {
                [pb, pa, mid].into_iter().map(|x| (q.eval(x), x)).fold(
                    (f64::INFINITY, mid),
                    |acc, c| if c.0 < acc.0 { c } else { acc },
                )
            });
            let plan = Plan {
                h: 2 * e,
                pos: best.1,
            };
            return best.0.is_finite().then_some((plan, best.0));
        }
        // One end stays: remove `v` into the other end if v may go along e.
        let removable = |v: u32| {
            let f = self.flags(v);
            f & (V_CORNER | V_LOCKED) == 0 && (f & V_FEATURE == 0 || ef & E_FEATURE != 0)
        };
        let mut best: Option<(Plan, f64)> = None;
        for (h, v, pos) in [(2 * e, a, pb), (2 * e + 1, b, pa)] {
            if !removable(v) {
                continue;
            }
            let c = q.eval(pos);
            if c.is_finite() && best.is_none_or(|x| c < x.1) {
                best = Some((Plan { h, pos }, c));
            }
        }
        best
    }

    /// Re-evaluates edge `e` and queues it under a new stamp (older entries
    /// become stale), unless its live entry already holds that evaluation.
    fn push(&mut self, e: u32) {
        let eu = e as usize;
        let eval = self.evaluate(e);
        if self.queued[eu] {
            if let Some((plan, cost)) = eval {
                if plan == self.plan[eu] && cost == self.cost[eu] {
                    return;
                }
            }
        }
        self.stamp[eu] = self.stamp[eu].wrapping_add(1);
        self.queued[eu] = false;
        if let Some((plan, cost)) = eval {
            self.plan[eu] = plan;
            self.cost[eu] = cost;
            self.queued[eu] = true;
            self.heap.push(Entry {
                cost,
                edge: e,
                stamp: self.stamp[eu],
            });
        }
    }

    /// May `from(h)` be removed into `to(h)` placed at `pos`? The link
    /// condition, no edge between two locked vertices, no two feature edges
    /// merged, and no face turned beyond the limit or made degenerate.
    fn valid(&self, h: u32, pos: [f64; 3]) -> bool {
        let m = &self.mesh;
        if !m.can_collapse(h) {
            return false;
        }
        let v = m.from_vertex(h);
        let w = m.to_vertex(h);
        if self.flags(w) & V_LOCKED != 0
            && m.neighbors(v)
                .any(|u| u != w && self.flags(u) & V_LOCKED != 0)
        {
            return false;
        }
        // Edges that merge: (prev(x), next(x)) of each face of the edge.
        let feat = |x: u32| m.edge_flags[m.edge(x) as usize] & E_FEATURE != 0;
        for x in [h, h ^ 1] {
            if m.face(x) != NONE && feat(m.prev(x)) && feat(m.next(x)) {
                return false;
            }
        }
        let moves_w = pos != m.positions[w as usize];
        self.star_ok(v, w, v, pos) && (!moves_w || self.star_ok(w, v, w, pos))
    }

    /// The faces around `c` not containing `other`, with `moved` placed at
    /// `pos`, stay non-degenerate and turn by at most the limit.
    fn star_ok(&self, c: u32, other: u32, moved: u32, pos: [f64; 3]) -> bool {
        let m = &self.mesh;
        for f in m.vertex_faces(c) {
            let vs = m.face_vertices(f);
            if vs.contains(&other) {
                continue;
            }
            let old = vs.map(|x| m.positions[x as usize]);
            let new = vs.map(|x| {
                if x == moved {
                    pos
                } else {
                    m.positions[x as usize]
                }
            });
            let n_new = cross(sub(new[1], new[0]), sub(new[2], new[0]));
            let l_new = norm(n_new);
            let longest = norm2(sub(new[1], new[0]))
                .max(norm2(sub(new[2], new[1])))
                .max(norm2(sub(new[0], new[2])));
            if !(l_new.is_finite() && l_new > MIN_FLATNESS * longest) {
                return false;
            }
            let n_old = cross(sub(old[1], old[0]), sub(old[2], old[0]));
            let l_old = norm(n_old);
            if l_old > 0.0 && dot(n_new, n_old) < self.cos_turn * l_new * l_old {
                return false;
            }
        }
        true
    }

    /// Collapses the cheapest valid edges until at most `target` faces are
    /// left or the queue is empty. Returns the number of collapses.
    fn run(&mut self, target: usize) -> usize {
        let mut count = 0;
        let mut ring: Vec<u32> = Vec::new();
        while self.mesh.face_count() > target {
            let Some(entry) = self.heap.pop() else {
                break;
            };
            let e = entry.edge as usize;
            if self.mesh.edge_deleted(entry.edge) || self.stamp[e] != entry.stamp {
                continue;
            }
            self.queued[e] = false;
            let Plan { h, pos } = self.plan[e];
            if !self.valid(h, pos) {
                continue;
            }
            let v = self.mesh.from_vertex(h);
            let w = self.mesh.to_vertex(h);
            let q = self.quadric[v as usize].add(&self.quadric[w as usize]);
            if self.mesh.collapse(h, pos).is_err() {
                continue;
            }
            self.quadric[w as usize] = q;
            count += 1;
            // Every edge touching the 1-ring of w may have changed: the cost
            // of those at w, the validity of all (an edge found invalid is
            // queued again). Edges away from w keep their ends' quadrics,
            // positions and flags, so a queued one keeps its entry.
            ring.clear();
            ring.push(w);
            ring.extend(self.mesh.neighbors(w));
            for &x in &ring {
                let hs: Vec<u32> = self.mesh.outgoing(x).collect();
                for hh in hs {
                    let ee = self.mesh.edge(hh);
                    let eu = ee as usize;
                    if self.touched[eu] != count {
                        self.touched[eu] = count;
                        if x == w || !self.queued[eu] {
                            self.push(ee);
                        }
                    }
                }
            }
        }
        count
    }
}

/// The live mesh as a grid, with sizes re-projected from `input` when it
/// has sizes.
fn output(mesh: &HalfedgeMesh, input: &Grid) -> Result<Grid> {
    let (verts, tris, _) = mesh.to_arrays(true);
    let sizes = match input.sizes() {
        Some(_) => {
            let mut h = vec![0.0; verts.len()];
            input.query_sizes(&verts, &mut h)?;
            Some(h)
        }
        None => None,
    };
    Grid::from_arrays(
        verts,
        tris,
        sizes,
        &BuildOptions {
            weld_relative_tolerance: None,
            orient: false,
        },
    )
}

#[cfg(test)]
mod tests;
