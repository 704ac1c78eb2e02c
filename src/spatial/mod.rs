//! Spatial indexing: a bounding-volume hierarchy over triangles, one per
//! label for searches restricted to a label, and two certified local
//! searches that answer near a known triangle without them: the star
//! search (within a label, for the simplifier's samples) and the prism walk
//! (the whole surface, for hinted size queries).

mod bvh;
mod forest;
mod layout;
mod prism;
mod ray;
mod star;
mod wide;

pub use bvh::{Bvh, ClosestHit, Node, MAX_DEPTH, MIXED_LABEL};
pub use forest::LabelForest;
pub use layout::BvhLayout;
pub(crate) use prism::walk_reach2;
pub use prism::{PrismMesh, PrismSlot, Prisms};
pub use ray::ray_triangle;
pub use star::{StarFace, StarMesh, StarTables};
