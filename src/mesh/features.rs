//! Feature edges and smooth patches.
//!
//! An edge is a *feature* when it is a boundary (one face), non-manifold (more
//! than two faces: bodies touching along it), or sharp (the angle between the
//! normals of its two faces exceeds a threshold, 30° by default). Smooth patches
//! are the connected components of faces across non-feature edges; they never
//! span two bodies. Corners are vertices with a feature valence other than 0 or 2.

use super::{Grid, Topology};
use crate::geometry::{dot, norm, scale, triangle_normal2};

/// Edge flag: one incident face.
pub const BOUNDARY: u8 = 1;
/// Edge flag: more than two incident faces.
pub const NON_MANIFOLD: u8 = 2;
/// Edge flag: dihedral angle above the threshold.
pub const SHARP: u8 = 4;

/// Feature edges, patches and corners of a grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Features {
    /// Threshold used for sharp edges, in degrees.
    pub angle_deg: f64,
    /// Per topology edge: a combination of [`BOUNDARY`], [`NON_MANIFOLD`], [`SHARP`] (0 = smooth).
    pub edge_flags: Vec<u8>,
    /// Smooth patch of each face, numbered 0.. in order of the lowest face index.
    pub face_patch: Vec<u32>,
    /// Number of patches.
    pub patch_count: u32,
    /// Number of feature edges at each vertex.
    pub vertex_feature_valence: Vec<u32>,
}

impl Features {
    /// Detects features with a dihedral threshold of `angle_deg` degrees. O(F).
    pub fn detect(grid: &Grid, angle_deg: f64) -> Features {
        detect(
            grid.vertices(),
            grid.triangles(),
            grid.topology(),
            angle_deg,
        )
    }

    /// True when edge `e` is a feature edge.
    #[inline]
    pub fn is_feature(&self, e: usize) -> bool {
        self.edge_flags[e] != 0
    }

    /// True when vertex `v` lies on a feature edge.
    #[inline]
    pub fn on_feature(&self, v: usize) -> bool {
        self.vertex_feature_valence[v] > 0
    }

    /// True when `v` is a corner (feature valence 1 or ≥ 3).
    #[inline]
    pub fn is_corner(&self, v: usize) -> bool {
        let k = self.vertex_feature_valence[v];
        k == 1 || k > 2
    }

    /// Number of feature edges.
    pub fn feature_edge_count(&self) -> usize {
        self.edge_flags.iter().filter(|&&f| f != 0).count()
    }
}

/// Unit normal of each triangle (zero for a degenerate one). O(F).
pub fn face_normals(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    triangles
        .iter()
        .map(|t| {
            let n = triangle_normal2(
                vertices[t[0] as usize],
                vertices[t[1] as usize],
                vertices[t[2] as usize],
            );
            let l = norm(n);
            if l > 0.0 {
                scale(n, 1.0 / l)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// See [`Features::detect`].
pub fn detect(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topo: &Topology,
    angle_deg: f64,
) -> Features {
    let normals = face_normals(vertices, triangles);
    let cos_t = angle_deg.to_radians().cos();
    let mut edge_flags = vec![0u8; topo.edges.len()];
    for (e, flag) in edge_flags.iter_mut().enumerate() {
        let fs = topo.faces_of_edge(e);
        *flag = match fs.len() {
            1 => BOUNDARY,
            2 => {
                let c = dot(normals[fs[0] as usize], normals[fs[1] as usize]);
                if c < cos_t {
                    SHARP
                } else {
                    0
                }
            }
            _ => NON_MANIFOLD,
        };
    }
    // Patches: components of faces across smooth edges.
    let (face_patch, patch_count) =
        topo.label_face_components(triangles.len(), |e| edge_flags[e] == 0);
    let mut vertex_feature_valence = vec![0u32; vertices.len()];
    for (e, &flag) in edge_flags.iter().enumerate() {
        if flag != 0 {
            for &v in &topo.edges[e] {
                vertex_feature_valence[v as usize] += 1;
            }
        }
    }
    Features {
        angle_deg,
        edge_flags,
        face_patch,
        patch_count,
        vertex_feature_valence,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildOptions;

    fn cube() -> Grid {
        let (v, t) = crate::mesh::validate::tests::cube();
        Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
    }

    #[test]
    fn cube_features() {
        let g = cube();
        let f = Features::detect(&g, 30.0);
        assert_eq!(f.feature_edge_count(), 12);
        assert_eq!(f.patch_count, 6);
        assert!((0..8).all(|v| f.is_corner(v)));
        // The diagonals inside each face are smooth.
        assert_eq!(f.edge_flags.iter().filter(|&&x| x == 0).count(), 6);
        let loose = Features::detect(&g, 95.0);
        assert_eq!(loose.feature_edge_count(), 0);
        assert_eq!(loose.patch_count, 1);
    }
}
