//! The order in which a batch of queries is answered: along a Morton (Z-order)
//! curve through the batch's bounding box, so that consecutive queries of a
//! worker lie near each other.
//!
//! # Why
//! A closest-point search is bound by memory latency: on a 100k-face grid its
//! hottest instructions are the first loads of the tree nodes and triangle
//! corners on its path, and near-surface points in random order cost about
//! twice a coherent walk's (occt_bearing_housing: 1.16 against 0.53 µs per
//! query). Points given in random order (a volume mesher's interior points,
//! a sampled cloud) touch a cold path each; points in curve order share most
//! of the path with their predecessor, whose answer also seeds the next
//! search's bound (the hint). The answers do not change: each is a function of
//! its point alone (ties to the lowest triangle), so the batch writes exactly
//! what the single queries would, in the caller's order.
//!
//! # Cost
//! O(n log n): one 63-bit code per point (21 bits per axis of the batch's
//! box), a parallel unstable sort of `(code, index)` pairs (a total order, so
//! the same permutation for any thread count); 20 bytes per point at most
//! while sorting (the keyed pairs and the order), 12 while the batch runs (the
//! order and the answers). The caller's order is kept below [`MIN_SORTED`] points and for
//! a batch that is coherent already: one whose consecutive points lie, on
//! average, within [`COHERENT_STEP`] of the batch's box diagonal of each
//! other (an advancing front's queries step by about an element size). There
//! the sort would cost a tenth of the queries' time and win nothing
//! (measured: a front walk of 100k points, 0.9× with the sort). The test is
//! one O(n) pass.
//!
//! # Ties
//! [`super`]'s batch queries use it; it knows nothing of the grid.

use rayon::prelude::*;

/// Batches smaller than this are answered in the caller's order: a few
/// hundred queries cost less than allocating and sorting for them.
pub const MIN_SORTED: usize = 1024;

/// A batch whose consecutive points are this close on average (a fraction of
/// its box diagonal) is answered in the caller's order. A random order steps
/// about half the diagonal; a front, an element size.
pub const COHERENT_STEP: f64 = 1.0 / 100.0;

/// Bits per axis of a Morton code.
const BITS: u32 = 21;

/// `v`'s low 21 bits spread to every third bit (bit `i` to bit `3i`).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The order in which to answer the batch `points` (finite, fewer than 2³²
/// of them): `None` to keep theirs (small or coherent batches, module doc),
/// else their indices in Morton order through their bounding box, ties
/// (equal codes) by index. O(n log n), parallel; the same for any thread
/// count.
pub fn batch_order(points: &[[f64; 3]]) -> Option<Vec<u32>> {
    if points.len() < MIN_SORTED {
        return None;
    }
    let (lo, hi) = bounds(points);
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    // Fixed chunks summed in order: the same total for any thread count.
    let steps: Vec<f64> = points
        .par_windows(2)
        .chunks(4096)
        .map(|c| {
            c.iter()
                .map(|w| crate::geometry::dist2(w[0], w[1]).sqrt())
                .sum()
        })
        .collect();
    let mean_step = steps.iter().sum::<f64>() / (points.len() - 1) as f64;
    if mean_step <= COHERENT_STEP * diagonal {
        return None;
    }
    Some(morton_order(points, lo, hi))
}

/// The bounding box of `points` as (lower, upper) corners. O(n), parallel.
fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    points
        .par_iter()
        .fold(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(mut lo, mut hi), p| {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
                (lo, hi)
            },
        )
        .reduce(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(a, b), (c, d)| {
                (
                    [a[0].min(c[0]), a[1].min(c[1]), a[2].min(c[2])],
                    [b[0].max(d[0]), b[1].max(d[1]), b[2].max(d[2])],
                )
            },
        )
}

/// The indices of `points` in Morton order through the box `lo..hi` (which
/// holds them), ties by index. O(n log n), parallel.
fn morton_order(points: &[[f64; 3]], lo: [f64; 3], hi: [f64; 3]) -> Vec<u32> {
    let cells = ((1u64 << BITS) - 1) as f64;
    // Cells per unit length along each axis (0 for a flat axis).
    let per: [f64; 3] = std::array::from_fn(|k| {
        let ext = hi[k] - lo[k];
        if ext > 0.0 && ext.is_finite() {
            cells / ext
        } else {
            0.0
        }
    });
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let mut code = 0u64;
            for k in 0..3 {
                // In [0, cells]: `as` saturates, and NaN (never: finite
                // points) would give 0.
                let c = ((p[k] - lo[k]) * per[k]).min(cells) as u64;
                code |= spread(c) << k;
            }
            (code, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1011), 0b1_000_001_001);
        assert_eq!(spread(0x1f_ffff), 0x1249_2492_4924_9249);
        let code = |x: u64, y: u64, z: u64| spread(x) | spread(y) << 1 | spread(z) << 2;
        assert_eq!(code(1, 0, 0), 1);
        assert_eq!(code(0, 1, 0), 2);
        assert_eq!(code(0, 0, 1), 4);
        assert_eq!(code(1, 1, 1), 7);
        assert_eq!(code(2, 0, 0), 8);
    }

    #[test]
    fn the_order_is_a_permutation_along_the_curve() {
        // A 4 × 4 × 4 lattice in scrambled order: the Morton order visits each
        // octant (2 × 2 × 2 block of cells) before the next.
        let mut pts = Vec::new();
        for i in 0..64u32 {
            let j = (i * 37) % 64;
            pts.push([(j % 4) as f64, ((j / 4) % 4) as f64, (j / 16) as f64]);
        }
        let order = sorted(&pts);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..64).collect::<Vec<u32>>());
        for block in order.chunks(8) {
            let octant = |i: u32| {
                let p = pts[i as usize];
                (p[0] >= 2.0, p[1] >= 2.0, p[2] >= 2.0)
            };
            assert!(block.iter().all(|&i| octant(i) == octant(block[0])));
        }
        // Equal points keep their index order; flat and empty batches work.
        assert_eq!(sorted(&[[1.0, 2.0, 3.0]; 5]), vec![0, 1, 2, 3, 4]);
        assert_eq!(sorted(&[[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]]), vec![1, 0]);
    }

    fn sorted(pts: &[[f64; 3]]) -> Vec<u32> {
        let (lo, hi) = bounds(pts);
        morton_order(pts, lo, hi)
    }

    #[test]
    fn small_and_coherent_batches_keep_their_order() {
        // A line walked in order, then the same points scrambled.
        let n = 4 * MIN_SORTED;
        let walk: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, 0.5 * i as f64, 0.0]).collect();
        assert!(batch_order(&walk).is_none());
        assert!(batch_order(&walk[..MIN_SORTED - 1]).is_none());
        let scrambled: Vec<[f64; 3]> = (0..n).map(|i| walk[(i * 7919) % n]).collect();
        let order = batch_order(&scrambled).expect("a scattered batch is sorted");
        // Sorted, it walks the line again (one way or the other).
        let x: Vec<f64> = order.iter().map(|&i| scrambled[i as usize][0]).collect();
        assert!(x.windows(2).all(|w| w[0] < w[1]) || x.windows(2).all(|w| w[0] > w[1]));
    }
}
