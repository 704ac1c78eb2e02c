//! Spatial indexing: a bounding-volume hierarchy over triangles.

mod bvh;

pub use bvh::{Bvh, ClosestHit, Node, MAX_DEPTH};
