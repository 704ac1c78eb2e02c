//! Small f64 geometry kernel: vector helpers, axis-aligned boxes, the exact closest
//! point on a triangle, and triangle quality measures.

mod closest;
mod vec3;

pub use closest::{
    closest_point_on_segment, closest_point_triangle, triangle_box_distance2, ClosestPoint,
};
pub use vec3::*;

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf); growing it by any point gives that point.
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// The smallest box holding all `points`. O(n).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            b.grow(p);
        }
        b
    }

    /// Grows the box to hold `p`.
    #[inline]
    pub fn grow(&mut self, p: &[f64; 3]) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }

    /// Grows the box to hold `other`.
    #[inline]
    pub fn merge(&mut self, other: &Aabb) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(other.min[k]);
            self.max[k] = self.max[k].max(other.max[k]);
        }
    }

    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            norm(sub(self.max, self.min))
        }
    }

    /// True when no point was added.
    pub fn is_empty(&self) -> bool {
        self.min[0] > self.max[0]
    }

    /// Centre of the box.
    pub fn center(&self) -> [f64; 3] {
        scale(add(self.min, self.max), 0.5)
    }

    /// Surface area (used by the SAH); 0 for an empty box.
    #[inline]
    pub fn area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let d = sub(self.max, self.min);
        2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
    }

    /// Squared distance from `p` to the box (0 inside).
    #[inline]
    pub fn distance2(&self, p: &[f64; 3]) -> f64 {
        let mut d2 = 0.0;
        for k in 0..3 {
            let v = (self.min[k] - p[k]).max(0.0).max(p[k] - self.max[k]);
            d2 += v * v;
        }
        d2
    }
}

/// The three interior angles of triangle (a, b, c) in degrees, at a, b and c.
/// A degenerate triangle gives NaN-free values (0 or 180 where a side vanishes).
pub fn triangle_angles_deg(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let ang = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| -> f64 {
        let u = sub(q, p);
        let v = sub(r, p);
        let y = norm(cross(u, v));
        let x = dot(u, v);
        y.atan2(x).to_degrees()
    };
    [ang(a, b, c), ang(b, c, a), ang(c, a, b)]
}

/// Twice the area vector of triangle (a, b, c): `(b - a) × (c - a)`.
#[inline]
pub fn triangle_normal2(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    cross(sub(b, a), sub(c, a))
}

/// Area of triangle (a, b, c).
#[inline]
pub fn triangle_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    0.5 * norm(triangle_normal2(a, b, c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aabb_distance() {
        let b = Aabb::from_points(&[[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]);
        assert_eq!(b.distance2(&[0.5, 1.0, 1.0]), 0.0);
        assert_eq!(b.distance2(&[2.0, 1.0, 1.0]), 1.0);
        assert_eq!(b.distance2(&[-1.0, -1.0, 1.0]), 2.0);
        assert!((b.diagonal() - 14f64.sqrt()).abs() < 1e-15);
        assert!(Aabb::EMPTY.is_empty());
    }

    #[test]
    fn angles_sum_to_180() {
        let a = triangle_angles_deg([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!((a[0] - 90.0).abs() < 1e-12);
        assert!((a[1] - 45.0).abs() < 1e-12);
        assert!((a.iter().sum::<f64>() - 180.0).abs() < 1e-12);
    }
}
