//! Spatial indexing: a bounding-volume hierarchy over triangles, one per
//! label for searches restricted to a label, and the certified star search
//! that answers near a known triangle without them.

mod bvh;
mod forest;
mod layout;
mod ray;
mod star;
mod wide;

pub use bvh::{Bvh, ClosestHit, Node, MAX_DEPTH, MIXED_LABEL};
pub use forest::LabelForest;
pub use layout::BvhLayout;
pub use ray::ray_triangle;
pub use star::StarMesh;
