//! Spatial indexing: a bounding-volume hierarchy over triangles.

mod bvh;
mod layout;
mod ray;

pub use bvh::{Bvh, ClosestHit, Node, MAX_DEPTH, MIXED_LABEL};
pub use layout::BvhLayout;
pub use ray::ray_triangle;
