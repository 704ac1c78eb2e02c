//! Spatial indexing: a bounding-volume hierarchy over triangles, and the
//! certified star search that answers near a known triangle without it.

mod bvh;
mod layout;
mod ray;
mod star;

pub use bvh::{Bvh, ClosestHit, Node, MAX_DEPTH, MIXED_LABEL};
pub use layout::BvhLayout;
pub use ray::ray_triangle;
pub use star::StarMesh;
