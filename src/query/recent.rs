//! The thread's last plain answer, as the hint of its next plain query.
//!
//! **Why.** An advancing-front or Delaunay mesher asks for sizes along its
//! front: each point lies a size or less from the last. A caller that can
//! carry a hint gets the certified walk ([`crate::spatial::Prisms`]); many
//! cannot: Gmsh's size callback receives a point and nothing else. So each
//! thread keeps one record of its last plain answer (`Grid::closest` with
//! no hint): the grid's id, the triangle, one of its corners and the radius
//! within which a walk from it is tried (four of its longest edges, the
//! walk's own bail-out: `walk_reach2`). A plain query within that radius of
//! the corner is asked as a hinted one.
//!
//! **Same answers.** A hint changes the time, never the answer (the walk
//! answers only under its certificate, bit for bit the BVH's, and seeds the
//! BVH otherwise), so what a thread asked before, on this grid or another,
//! cannot change a size: plain answers stay a function of the point alone,
//! whatever the threads and the order.
//!
//! **Cost.** A scattered point set pays a thread-local read, one distance
//! test against the record (no read of the grid) and a store of the new
//! record from the answer's corners, which the search has just read.
//! (Carrying the answer's BVH slot out of the search, to skip the one
//! lookup of triangle → slot, was tried: no difference beyond noise.)
//! Measured in one process against queries that neither read nor leave a
//! record: 0.95–1.00 of their speed near the surface, 0.98–1.03 uniform in
//! the box (README, "Plain queries along a front"). A coherent set answers
//! most points in O(1) with the walk: 1.09–2.07× faster on the harness's
//! front walk (one alternating run of the 8 dense grids; this machine's
//! reruns move more than that). The first query that uses a record builds the grid's prism
//! table (O(F log F), parallel; once per grid).
//!
//! **Ties.** To the walk: the reach is [`crate::spatial::Prisms::closest_from`]'s
//! own bail-out, so a record never starts a walk that the walk would refuse.
//! To the grid: grids are told apart by an id drawn once per grid from a
//! process-wide counter (a clone keeps its original's id and its geometry);
//! a record of another grid is ignored, and a stale one could cost at most
//! the walk's bail-out, never an answer.

use crate::spatial::{walk_reach2, Bvh};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// The last plain answer of this thread (see the module doc).
#[derive(Clone, Copy)]
struct Recent {
    /// Id of the grid it was given on.
    grid: u64,
    /// The answer's triangle.
    triangle: u32,
    /// Its first corner in the BVH's corner order (the walk's anchor).
    anchor: [f64; 3],
    /// Squared radius around `anchor` within which the walk is tried.
    reach2: f64,
}

thread_local! {
    static RECENT: Cell<Option<Recent>> = const { Cell::new(None) };
}

/// Source of grid ids (0 is never drawn).
static NEXT_GRID_ID: AtomicU64 = AtomicU64::new(1);

/// A new grid id, distinct from every other drawn in this process. O(1).
pub(crate) fn new_grid_id() -> u64 {
    NEXT_GRID_ID.fetch_add(1, Ordering::Relaxed)
}

/// The thread's last plain answer on grid `grid` as a hint for `p`, if `p`
/// lies within its reach. O(1); reads no grid memory.
pub(crate) fn hint_for(grid: u64, p: &[f64; 3]) -> Option<u32> {
    let r = RECENT.try_with(Cell::get).ok().flatten()?;
    let d2: f64 = (0..3).map(|k| (p[k] - r.anchor[k]).powi(2)).sum();
    (r.grid == grid && d2 <= r.reach2).then_some(r.triangle)
}

/// Records `triangle` (an answer on grid `grid`, searched in `bvh`) as the
/// thread's last plain answer. O(1): its corners were just read by the search.
pub(crate) fn remember(grid: u64, bvh: &Bvh, triangle: u32) {
    let Some(&slot) = bvh.triangle_prim.get(triangle as usize) else {
        return;
    };
    let c = &bvh.prim_corners[slot as usize];
    let record = Recent {
        grid,
        triangle,
        anchor: c[0],
        reach2: walk_reach2(c),
    };
    // During the thread's teardown there is no record to keep: nothing lost.
    let _ = RECENT.try_with(|r| r.set(Some(record)));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{BuildOptions, Grid};
    use crate::query::QueryHit;
    use crate::test_shapes::{rng, touching_sheets, unit_square};

    fn wave(x: f64, y: f64) -> f64 {
        0.05 * (6.0 * x).sin() * (5.0 * y).cos()
    }

    /// A wavy sheet (40 × 40 squares) with a linear size field.
    fn wavy() -> Grid {
        let (v, t) = unit_square(40, wave);
        let s = v.iter().map(|p| 0.1 + p[0] + 0.5 * p[1]).collect();
        Grid::from_arrays(v, t, Some(s), &BuildOptions::default()).unwrap()
    }

    /// A front-like walk over [-0.2, 1.2]², within 0.003 of [`wavy`]'s
    /// surface (an eighth of an edge: most points certified by the walk):
    /// steps of 0.01, a jump anywhere every 50 points.
    fn walk(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut s = seed;
        let mut p = [0.5, 0.5, 0.0];
        (0..n)
            .map(|i| {
                if i % 50 == 0 {
                    p = [1.4 * rng(&mut s) - 0.2, 1.4 * rng(&mut s) - 0.2, 0.0];
                }
                p[0] += 0.02 * rng(&mut s) - 0.01;
                p[1] += 0.02 * rng(&mut s) - 0.01;
                p[2] = wave(p[0], p[1]) + 0.006 * rng(&mut s) - 0.003;
                p
            })
            .collect()
    }

    fn bits(h: &QueryHit) -> (u32, Vec<u64>) {
        let f = h.bary.iter().chain(&h.point).chain([&h.distance, &h.size]);
        (h.triangle, f.map(|x| x.to_bits()).collect())
    }

    /// Plain queries along a walk (records in use) answer as a query that
    /// neither reads nor leaves a record (an out-of-range hint), bit for
    /// bit, on one body and at contacts of several; two grids queried in
    /// turn on one thread do not disturb each other.
    #[test]
    fn plain_answers_along_a_walk_are_those_without_a_record() {
        let (a, b) = (wavy(), touching_sheets());
        for (i, p) in walk(2000, 5).into_iter().enumerate() {
            let g = if i % 3 == 0 { &b } else { &a };
            let plain = g.closest(p, None).unwrap();
            let fresh = g.closest(p, Some(u32::MAX)).unwrap();
            assert_eq!(bits(&plain), bits(&fresh), "point {i} {p:?}");
        }
    }

    /// The record: the last plain answer's triangle, for points near it on
    /// the same grid only, per thread; hinted queries leave it alone.
    #[test]
    fn the_record_serves_nearby_points_of_the_same_grid_only() {
        let (a, b) = (wavy(), wavy());
        assert_ne!(a.id(), b.id());
        assert_eq!(a.clone().id(), a.id());
        let near = [0.31, 0.6, 0.0];
        assert_eq!(hint_for(a.id(), &near), None);
        let hit = a.closest([0.3, 0.6, 0.01], None).unwrap();
        assert_eq!(hint_for(a.id(), &near), Some(hit.triangle));
        assert_eq!(hint_for(b.id(), &near), None);
        // 0.6 away: beyond four longest edges (0.035) of the triangle.
        assert_eq!(hint_for(a.id(), &[0.9, 0.1, 0.0]), None);
        a.closest([0.9, 0.1, 0.0], Some(0)).unwrap();
        assert_eq!(hint_for(a.id(), &near), Some(hit.triangle));
        let id = a.id();
        std::thread::spawn(move || assert_eq!(hint_for(id, &near), None))
            .join()
            .unwrap();
        // A plain query on another grid replaces the record.
        b.closest(near, None).unwrap();
        assert_eq!(hint_for(a.id(), &near), None);
        assert!(hint_for(b.id(), &near).is_some());
    }
}
