//! Vertex normals per smooth patch: a vertex on a feature line has one normal
//! per patch around it (a cube corner has three), so nothing is averaged across
//! a sharp edge or between bodies.

use crate::geometry::*;
use crate::mesh::{features::face_normals, Features, Grid};
use rayon::prelude::*;

/// The normals of every vertex, one per patch around it, in CSR layout.
#[derive(Debug, Clone)]
pub struct PatchNormals {
    /// Entries of vertex `v` are `offsets[v]..offsets[v + 1]`.
    pub offsets: Vec<u32>,
    /// Patch of each entry (ascending per vertex).
    pub patch: Vec<u32>,
    /// Unit angle-weighted normal of each entry.
    pub normal: Vec<[f64; 3]>,
    /// Unit normal of each face.
    pub face_normal: Vec<[f64; 3]>,
}

/// Interior angle at corner `k` of triangle `t`.
#[inline]
pub fn corner_angle(v: &[[f64; 3]], t: &[u32; 3], k: usize) -> f64 {
    let p = v[t[k] as usize];
    let a = sub(v[t[(k + 1) % 3] as usize], p);
    let b = sub(v[t[(k + 2) % 3] as usize], p);
    norm(cross(a, b)).atan2(dot(a, b))
}

impl PatchNormals {
    /// Computes the normals. O(F), parallel over vertices.
    pub fn compute(grid: &Grid, features: &Features) -> PatchNormals {
        let v = grid.vertices();
        let tris = grid.triangles();
        let topo = grid.topology();
        let face_normal = face_normals(v, tris);
        let per_vertex: Vec<Vec<(u32, [f64; 3])>> = (0..v.len())
            .into_par_iter()
            .map(|vi| {
                let mut acc: Vec<(u32, [f64; 3])> = Vec::new();
                for &f in topo.faces_of_vertex(vi) {
                    let t = &tris[f as usize];
                    let k = t.iter().position(|&x| x as usize == vi).unwrap_or(0);
                    let w = corner_angle(v, t, k);
                    let p = features.face_patch[f as usize];
                    let n = scale(face_normal[f as usize], w);
                    match acc.iter_mut().find(|e| e.0 == p) {
                        Some(e) => e.1 = add(e.1, n),
                        None => acc.push((p, n)),
                    }
                }
                acc.sort_by_key(|e| e.0);
                for e in &mut acc {
                    let l = norm(e.1);
                    if l > 0.0 {
                        e.1 = scale(e.1, 1.0 / l);
                    }
                }
                acc
            })
            .collect();
        let mut offsets = Vec::with_capacity(v.len() + 1);
        offsets.push(0u32);
        let mut patch = Vec::new();
        let mut normal = Vec::new();
        for list in per_vertex {
            for (p, n) in list {
                patch.push(p);
                normal.push(n);
            }
            offsets.push(patch.len() as u32);
        }
        PatchNormals {
            offsets,
            patch,
            normal,
            face_normal,
        }
    }

    /// Entry range of vertex `v`.
    #[inline]
    pub fn range(&self, v: usize) -> std::ops::Range<usize> {
        self.offsets[v] as usize..self.offsets[v + 1] as usize
    }
}
