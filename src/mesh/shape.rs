//! Triangle-quality predicates shared by the remesher and the simplifiers:
//! angles, flatness, trustworthy normals, and whether a move or a flip keeps
//! faces sound. All O(1) per triangle.

use crate::geometry::{cross, dot, norm, norm2, sub};
use crate::mesh::halfedge::HalfedgeMesh;

/// Smallest interior angle of a triangle, in degrees (0 when degenerate).
pub fn min_angle_deg(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let ang = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| {
        let (u, v) = (sub(q, p), sub(r, p));
        norm(cross(u, v)).atan2(dot(u, v))
    };
    ang(a, b, c)
        .min(ang(b, c, a))
        .min(ang(c, a, b))
        .to_degrees()
}

/// `n` scaled to unit length (`None` when zero or not finite).
pub fn unit(n: [f64; 3]) -> Option<[f64; 3]> {
    let l = norm(n);
    (l > 0.0 && l.is_finite()).then(|| [n[0] / l, n[1] / l, n[2] / l])
}

/// Shape measure of triangle (a, b, c): `|ab × ac| / (longest side)²`, twice
/// the height over the longest side divided by it (0 when degenerate, √3/2
/// when equilateral).
pub fn flatness(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let l = norm(cross(sub(b, a), sub(c, a)));
    let m = norm2(sub(b, a)).max(norm2(sub(c, b))).max(norm2(sub(a, c)));
    if m > 0.0 && l.is_finite() {
        l / m
    } else {
        0.0
    }
}

/// A move of a face from `old` corners to `new` corners keeps it sound: it
/// does not become a sliver (flatness below 0.01) unless it was one, and then
/// it does not get flatter.
pub fn keeps_shape(old: [[f64; 3]; 3], new: [[f64; 3]; 3]) -> bool {
    let q = flatness(new[0], new[1], new[2]);
    q > 0.0 && q >= flatness(old[0], old[1], old[2]).min(0.01)
}

/// Unit normal of triangle (a, b, c) when its direction is trustworthy: the
/// height over the longest side is at least 1 % of that side (no angle below
/// about 0.6°). Slivers and caps have noise for a normal and give `None`.
pub fn reliable_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[f64; 3]> {
    let n = cross(sub(b, a), sub(c, a));
    let l = norm(n);
    let m = norm2(sub(b, a)).max(norm2(sub(c, b))).max(norm2(sub(a, c)));
    (l.is_finite() && l > 0.01 * m).then(|| [n[0] / l, n[1] / l, n[2] / l])
}

/// Largest interior angle of a triangle, degrees.
pub fn max_angle_deg(p: [[f64; 3]; 3]) -> f64 {
    let t = crate::geometry::triangle_angles_deg(p[0], p[1], p[2]);
    t[0].max(t[1]).max(t[2])
}

/// Is flipping edge `e` geometrically sound: both new faces non-degenerate,
/// their normals within the turn limit of the old ones, no new crease, and
/// the smallest angle not made worse than `min(old, floor_deg)`? `cos_turn`:
/// cosine of the largest normal turn; `cos_crease`: of the largest dihedral
/// angle a flip may create. O(1).
pub fn flip_sound(
    mesh: &HalfedgeMesh,
    e: u32,
    cos_turn: f64,
    cos_crease: f64,
    floor_deg: f64,
) -> bool {
    let [a, b] = mesh.edge_vertices(e);
    let [c, d] = mesh.flip_apexes(e);
    let [pa, pb, pc, pd] = [a, b, c, d].map(|x| mesh.positions[x as usize]);
    let n = |x: [f64; 3], y: [f64; 3], z: [f64; 3]| unit(cross(sub(y, x), sub(z, x)));
    let (Some(o1), Some(o2)) = (reliable_normal(pa, pb, pc), reliable_normal(pb, pa, pd)) else {
        // A degenerate old face: a flatter-free new pair that agrees with itself.
        let q_old = flatness(pa, pb, pc).min(flatness(pb, pa, pd));
        let q_new = flatness(pa, pd, pc).min(flatness(pd, pb, pc));
        return q_new > q_old
            && match (n(pa, pd, pc), n(pd, pb, pc)) {
                (Some(n1), Some(n2)) => dot(n1, n2) >= cos_turn,
                _ => false,
            };
    };
    let (Some(n1), Some(n2)) = (n(pa, pd, pc), n(pd, pb, pc)) else {
        return false;
    };
    for nn in [n1, n2] {
        if dot(nn, o1) < cos_turn || dot(nn, o2) < cos_turn {
            return false;
        }
    }
    if dot(n1, n2) < dot(o1, o2).min(cos_crease) {
        return false;
    }
    let q_old = min_angle_deg(pa, pb, pc).min(min_angle_deg(pb, pa, pd));
    let q_new = min_angle_deg(pa, pd, pc).min(min_angle_deg(pd, pb, pc));
    q_new >= q_old.min(floor_deg)
}
