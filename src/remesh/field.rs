//! The cap on the target edge length: per input vertex, half the curvature
//! size `h = 2π / (κ · n_circle)` where the surface or a feature line bends,
//! and a crease size where two input facets meet at an angle below the
//! feature angle; then spread as a graded field of sources (points on
//! feature lines, crease edges, curved input faces), so it grows by at most
//! `slope` per unit distance (abrupt jumps make bad triangles). Sources are
//! whole edges and faces, not only vertices: CAD tessellations have needle
//! triangles hundreds of target lengths long whose curvature (a fillet along
//! a panel) must reach their middle, not only their corners.

use crate::geometry::{closest_point_triangle, dot, norm, sub};
use crate::mesh::{Features, Grid};
use crate::sizing::curvature::patch_curvatures;
use crate::sizing::normals::PatchNormals;
use crate::spatial::{Bvh, MAX_DEPTH};
use arrayvec::ArrayVec;
use std::cell::Cell;
use std::f64::consts::PI;

/// Target length across a strip of width w: `STRIP_RATIO · w` (triangles
/// spanning it are then about equilateral).
const STRIP_RATIO: f64 = 1.2;

/// Settings of [`length_cap`].
#[derive(Debug, Clone)]
pub struct CapSettings {
    /// Base target length at each input vertex (uniform length, or the sizing
    /// field there).
    pub base: Vec<f64>,
    /// Lower the cap by curvature.
    pub curvature: bool,
    /// Elements per full circle.
    pub n_circle: f64,
    /// Smallest curvature cap as a fraction of the base.
    pub min_ratio: f64,
    /// Smallest cap from the curvature of a feature line, as a fraction of the base.
    pub line_min_ratio: f64,
    /// Largest distance (fraction of the base) a chord may cut off a crease
    /// (an edge sharper than nothing but below the feature angle).
    pub crease_tolerance: f64,
    /// Feature lines turning by more than this (degrees) at a vertex have a
    /// corner there, not a curvature.
    pub corner_deg: f64,
}

/// A source of the cap: a point, segment or triangle (repeated corners) and
/// the cap on it.
pub type Source = ([[f64; 3]; 3], f64);

/// The cap sources (only finite caps); `width` is [`patch_widths`]. O(F).
pub fn length_cap(grid: &Grid, features: &Features, width: &[f64], s: &CapSettings) -> Vec<Source> {
    let nv = grid.vertices().len();
    let mut cap = vec![f64::INFINITY; nv];
    let mut out: Vec<Source> = Vec::new();
    if !s.curvature {
        return out;
    }
    let floor = |v: usize| s.min_ratio * s.base[v];
    let from_kappa = |k: f64, floor: f64| -> f64 {
        if k > 0.0 && k.is_finite() {
            (0.5 * 2.0 * PI / (k * s.n_circle)).max(floor)
        } else {
            f64::INFINITY
        }
    };
    let normals = PatchNormals::compute(grid, features);
    let per_patch = patch_curvatures(grid, features, &normals);
    for vi in 0..nv {
        for e in normals.range(vi) {
            cap[vi] = cap[vi].min(from_kappa(per_patch[e].max_abs(), floor(vi)));
        }
    }
    let v = grid.vertices();
    let tris = grid.triangles();
    let topo = grid.topology();
    // Each face whose corners all bend in its patch is a source too, with the
    // smallest of their curvatures: a fillet tessellated by needles then
    // limits the length along its whole span, not only near its corners,
    // while a flat face fanned from a curved rim stays free (its corners'
    // curvature in its own patch is zero).
    let entry = |vi: usize, patch: u32| {
        let r = normals.range(vi);
        normals.patch[r.clone()]
            .iter()
            .position(|&p| p == patch)
            .map(|k| r.start + k)
    };
    for (f, t) in tris.iter().enumerate() {
        let patch = features.face_patch[f];
        let k = t
            .iter()
            .map(|&i| entry(i as usize, patch).map_or(0.0, |e| per_patch[e].max_abs()))
            .fold(f64::INFINITY, f64::min);
        let floor_f = t
            .iter()
            .map(|&i| floor(i as usize))
            .fold(f64::INFINITY, f64::min);
        let c = from_kappa(k, floor_f);
        if c.is_finite() {
            out.push((t.map(|i| v[i as usize]), c));
        }
    }
    // Strips: a smooth patch narrower than its target length (a plate's rim
    // between two sharp edges) is meshed across its width, so its rims are
    // refined to about that width and the triangles spanning it are not
    // slivers. Width: see [`patch_widths`].
    {
        let mut base = vec![f64::INFINITY; width.len()];
        for (f, t) in tris.iter().enumerate() {
            let p = features.face_patch[f] as usize;
            for &i in t {
                base[p] = base[p].min(s.base[i as usize]);
            }
        }
        let floor_p = |p: usize| s.line_min_ratio * base[p];
        // Strips narrower than the floor (a foil's edge) are left unrefined:
        // refining their rims to the floor would only multiply the slivers
        // spanning them.
        for (f, t) in tris.iter().enumerate() {
            let p = features.face_patch[f] as usize;
            let c = STRIP_RATIO * width[p];
            if c < base[p] && c >= floor_p(p) {
                out.push((t.map(|i| v[i as usize]), c));
            }
        }
    }
    // Creases below the feature angle: a chord of length L across a crease of
    // angle φ cuts off about L·φ/4, so L ≤ 4·tolerance·base/φ keeps the cut
    // within tolerance. (Curvature fits see a crease between large facets as
    // a gentle bend.)
    let fnormal = &normals.face_normal;
    for e in 0..topo.edges.len() {
        let fs = topo.faces_of_edge(e);
        if fs.len() != 2 || features.is_feature(e) {
            continue;
        }
        let phi = dot(fnormal[fs[0] as usize], fnormal[fs[1] as usize])
            .clamp(-1.0, 1.0)
            .acos();
        if phi > 1e-3 {
            let [a, b] = topo.edges[e].map(|i| i as usize);
            let l = (4.0 * s.crease_tolerance * s.base[a].min(s.base[b]) / phi)
                .max(floor(a).min(floor(b)));
            out.push(([v[a], v[b], v[b]], l));
        }
    }
    // Curvature of feature lines: turning angle over the mean segment length.
    let cos_c = s.corner_deg.to_radians().cos();
    let mut ends: Vec<u32> = Vec::new();
    for (vi, c) in cap.iter_mut().enumerate() {
        if features.vertex_feature_valence[vi] != 2 {
            continue;
        }
        ends.clear();
        for &f in topo.faces_of_vertex(vi) {
            for &e in &topo.face_edges[f as usize] {
                let [a, b] = topo.edges[e as usize];
                if features.is_feature(e as usize) && (a as usize == vi || b as usize == vi) {
                    let o = if a as usize == vi { b } else { a };
                    if !ends.contains(&o) {
                        ends.push(o);
                    }
                }
            }
        }
        if ends.len() != 2 {
            continue;
        }
        let p = v[vi];
        let d1 = sub(p, v[ends[0] as usize]);
        let d2 = sub(v[ends[1] as usize], p);
        let (l1, l2) = (norm(d1), norm(d2));
        if !(l1 > 0.0 && l2 > 0.0) {
            continue;
        }
        let cos = (dot(d1, d2) / (l1 * l2)).clamp(-1.0, 1.0);
        if cos < cos_c {
            continue;
        }
        let k = cos.acos() / (0.5 * (l1 + l2));
        *c = c.min(from_kappa(k, s.line_min_ratio * s.base[vi]));
    }
    for (vi, &c) in cap.iter().enumerate() {
        if c.is_finite() {
            out.push(([v[vi]; 3], c));
        }
    }
    out
}

/// Width of each smooth patch: twice its area over the length of its feature
/// rims (exact for a long strip, the radius of a disc; ∞ for a patch without
/// feature rims). O(F).
pub fn patch_widths(grid: &Grid, features: &Features) -> Vec<f64> {
    let np = features.patch_count as usize;
    let (v, topo) = (grid.vertices(), grid.topology());
    let mut area = vec![0.0; np];
    let mut perimeter = vec![0.0; np];
    for (f, t) in grid.triangles().iter().enumerate() {
        let p = features.face_patch[f] as usize;
        area[p] +=
            crate::geometry::triangle_area(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        for &e in &topo.face_edges[f] {
            if features.is_feature(e as usize) {
                let [a, b] = topo.edges[e as usize];
                perimeter[p] += norm(sub(v[a as usize], v[b as usize]));
            }
        }
    }
    (0..np)
        .map(|p| {
            if perimeter[p] > 0.0 {
                2.0 * area[p] / perimeter[p]
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// A graded size field from sources: `f(x) = min_i (h_i + slope·d(x, S_i))`
/// (∞ without sources) with `S_i` a point, segment or triangle, evaluated
/// exactly by branch and bound over a BVH of the sources with the smallest
/// value per node. Unlike values interpolated on the input triangles, it grows
/// away from a small source whatever the input tessellation (a planar face
/// tessellated only at its rim still gets large elements inside).
#[derive(Debug, Clone, Default)]
pub struct SourceField {
    bvh: Bvh,
    value: Vec<f64>,
    node_min: Vec<f64>,
    slope: f64,
}

impl SourceField {
    /// The field of `sources` (non-finite values are ignored) and growth
    /// `slope` (> 0). O(n log n).
    pub fn new(sources: &[Source], slope: f64) -> SourceField {
        let keep: Vec<&Source> = sources.iter().filter(|s| s.1.is_finite()).collect();
        let pts: Vec<[f64; 3]> = keep.iter().flat_map(|s| s.0).collect();
        let value: Vec<f64> = keep.iter().map(|s| s.1).collect();
        let tris: Vec<[u32; 3]> = (0..keep.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let bvh = Bvh::build(&pts, &tris);
        let node_min = bvh.node_minima(&value);
        SourceField {
            bvh,
            value,
            node_min,
            slope: if slope.is_finite() && slope > 0.0 {
                slope
            } else {
                1e-12
            },
        }
    }

    /// `f(p)`. Expected O(log n).
    pub fn eval(&self, p: [f64; 3]) -> f64 {
        if self.bvh.nodes.is_empty() {
            return f64::INFINITY;
        }
        let slots = self.bvh.prim_corners.len();
        let candidate = |slot: usize| {
            let [a, b, c] = self.bvh.prim_corners[slot];
            let i = self.bvh.prim_triangle[slot] as usize;
            self.value[i] + self.slope * closest_point_triangle(p, a, b, c).dist2.sqrt()
        };
        // Seed the bound with the source that won this thread's last query
        // (queries come in runs of nearby points), so most of the tree is
        // pruned at once.
        let seed = LAST_SOURCE.with(Cell::get) as usize;
        let (mut best, mut best_slot) = if seed < slots {
            (candidate(seed), seed)
        } else {
            (f64::INFINITY, usize::MAX)
        };
        // Uninitialised storage; one net entry per level, so within capacity.
        // Each entry carries its node's bound, computed once when pushed (a
        // square root per node, not two; the same pruning decisions).
        let mut stack: ArrayVec<(f64, u32), { MAX_DEPTH + 1 }> = ArrayVec::new();
        let root = &self.bvh.nodes[0];
        stack.push((
            self.node_min[0] + self.slope * root.bbox.distance2(&p).sqrt(),
            0,
        ));
        while let Some((bound, ni)) = stack.pop() {
            if pruned(bound, best) {
                continue;
            }
            let ni = ni as usize;
            let n = &self.bvh.nodes[ni];
            if n.is_leaf() {
                let s = n.start as usize;
                for slot in s..s + n.count as usize {
                    let c = candidate(slot);
                    if c < best {
                        (best, best_slot) = (c, slot);
                    }
                }
            } else {
                let (l, r) = (ni + 1, n.start as usize);
                let dl =
                    self.node_min[l] + self.slope * self.bvh.nodes[l].bbox.distance2(&p).sqrt();
                let dr =
                    self.node_min[r] + self.slope * self.bvh.nodes[r].bbox.distance2(&p).sqrt();
                // Visit the more promising child first; a child already
                // beyond the best is not pushed.
                let (first, second) = if dl <= dr {
                    ((dl, l), (dr, r))
                } else {
                    ((dr, r), (dl, l))
                };
                if !pruned(second.0, best) {
                    stack.push((second.0, second.1 as u32));
                }
                if !pruned(first.0, best) {
                    stack.push((first.0, first.1 as u32));
                }
            }
        }
        if best_slot < slots {
            LAST_SOURCE.with(|x| x.set(best_slot as u32));
        }
        best
    }
}

thread_local! {
    /// The source slot that gave this thread's last [`SourceField::eval`]
    /// value: only a first bound, checked against the field's size, so a
    /// slot of another field or a stale one costs a little pruning, never a
    /// wrong value.
    static LAST_SOURCE: Cell<u32> = const { Cell::new(u32::MAX) };
}

/// May a node whose lower bound is `bound` be skipped when the best value so
/// far is `best`? Only when the bound exceeds it by more than rounding: a
/// node's bound (its least value plus the slope times its box distance) can
/// exceed the value of a source inside by a few units in the last place
/// only, so the least value is never pruned, whatever bound the search
/// started from, and the result is the same for any seed (and any thread).
#[inline(always)]
fn pruned(bound: f64, best: f64) -> bool {
    bound > best * (1.0 + 1e-12)
}
