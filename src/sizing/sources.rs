//! User size sources: a point, segment or triangle with a size and a radius of
//! influence. Every vertex within the radius of the source geometry gets at most
//! that size (gradation then blends it into the surroundings).

use crate::error::{Error, Result};
use crate::geometry::*;

/// The geometry of a source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SourceShape {
    /// A point.
    Point([f64; 3]),
    /// A segment between two points.
    Segment([f64; 3], [f64; 3]),
    /// A triangle.
    Triangle([f64; 3], [f64; 3], [f64; 3]),
}

/// A size source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeSource {
    /// Where it acts.
    pub shape: SourceShape,
    /// Size imposed within the radius (finite, > 0).
    pub size: f64,
    /// Radius of influence (finite, ≥ 0).
    pub radius: f64,
}

impl SizeSource {
    /// Distance from `p` to the source geometry. O(1).
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        match self.shape {
            SourceShape::Point(a) => norm(sub(p, a)),
            SourceShape::Segment(a, b) => {
                norm(sub(p, lerp(a, b, closest_point_on_segment(p, a, b))))
            }
            SourceShape::Triangle(a, b, c) => closest_point_triangle(p, a, b, c).dist2.sqrt(),
        }
    }

    /// Checks coordinates, size and radius.
    pub fn validate(&self) -> Result<()> {
        let pts: Vec<[f64; 3]> = match self.shape {
            SourceShape::Point(a) => vec![a],
            SourceShape::Segment(a, b) => vec![a, b],
            SourceShape::Triangle(a, b, c) => vec![a, b, c],
        };
        if !pts.iter().all(|p| is_finite3(*p)) {
            return Err(Error::NonFinite(format!("size source {:?}", self.shape)));
        }
        if !(self.size.is_finite() && self.size > 0.0) {
            return Err(Error::InvalidSize(format!(
                "size source size {}",
                self.size
            )));
        }
        if !(self.radius.is_finite() && self.radius >= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "size source radius {}",
                self.radius
            )));
        }
        Ok(())
    }
}
