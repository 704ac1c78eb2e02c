//! Welding of coincident vertices (STL stores every triangle corner separately).

use kiddo::{ImmutableKdTree, SquaredEuclidean};

/// Merges vertices closer than `tolerance` (absolute, model units).
///
/// Returns `(kept_vertices, remap)` where `remap[i]` is the new index of input
/// vertex `i`. Vertices are visited in input order; the first vertex of a cluster
/// is kept (its coordinates are not averaged, so nothing moves). Deterministic.
/// O(n log n) with a kiddo kd-tree; `tolerance == 0` merges bit-identical points.
pub fn weld(vertices: &[[f64; 3]], tolerance: f64) -> (Vec<[f64; 3]>, Vec<u32>) {
    let n = vertices.len();
    let mut remap = vec![u32::MAX; n];
    let mut kept = Vec::new();
    if n == 0 {
        return (kept, remap);
    }
    let tree = match ImmutableKdTree::<f64, 3>::new_from_slice(vertices) {
        Ok(t) => t,
        Err(_) => return exact_weld(vertices),
    };
    let r2 = tolerance * tolerance;
    for i in 0..n {
        if remap[i] != u32::MAX {
            continue;
        }
        let id = kept.len() as u32;
        kept.push(vertices[i]);
        remap[i] = id;
        let near = tree
            .query(&vertices[i])
            .within::<SquaredEuclidean<f64>>(r2)
            .unsorted()
            .execute();
        for hit in near {
            let j = hit.item as usize;
            if remap[j] == u32::MAX {
                remap[j] = id;
            }
        }
    }
    (kept, remap)
}

/// Fallback: merge only bit-identical coordinates (sort-based, O(n log n)).
fn exact_weld(vertices: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<u32>) {
    let mut order: Vec<u32> = (0..vertices.len() as u32).collect();
    let key = |i: u32| vertices[i as usize].map(f64::to_bits);
    order.sort_by_key(|&i| (key(i), i));
    let mut first = vec![0u32; vertices.len()];
    let mut k = 0;
    while k < order.len() {
        let mut m = k;
        while m < order.len() && key(order[m]) == key(order[k]) {
            first[order[m] as usize] = order[k];
            m += 1;
        }
        k = m;
    }
    let mut remap = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    for i in 0..vertices.len() {
        let f = first[i] as usize;
        if remap[f] == u32::MAX {
            remap[f] = kept.len() as u32;
            kept.push(vertices[f]);
        }
        remap[i] = remap[f];
    }
    (kept, remap)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merges_within_tolerance_only() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1e-9, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.0, 0.0],
        ];
        let (kept, remap) = weld(&v, 1e-6);
        assert_eq!(kept.len(), 3);
        assert_eq!(remap, vec![0, 1, 0, 1, 2]);
        assert_eq!(kept[0], [0.0, 0.0, 0.0]);
        let (kept, remap) = exact_weld(&v);
        assert_eq!(kept.len(), 4);
        assert_eq!(remap, vec![0, 1, 2, 1, 3]);
    }
}
