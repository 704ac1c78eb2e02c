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
//! **Back-off.** A walk from the record that misses (its certificate does
//! not hold and the descent finds another triangle than the one the walk
//! ended on) and a point beyond the record's reach both count as a miss; a
//! certified walk, or one that ended on the answer and so seeded the
//! descent with its exact bound, clears the count. From the third miss in
//! a row the record is set aside for 1, 2, 4, … up to 64 plain queries,
//! which then neither test nor refresh it. Points in random order stop
//! paying for walks that cannot help: on a coarse grid, whose long edges
//! put most of the part within a record's reach, they walked up to eight
//! steps and then descended anyway (gmsh_t20_component8's simplified grid:
//! 0.64–0.68 of the speed of queries without a record, 0.93–0.98 with the
//! back-off); a front, whose misses are rare and isolated, keeps the walk.
//! The caller's own hints get the same rule, counted apart (a second
//! thread-local count per grid): a caller that chains hints through points
//! in random order (a Delaunay mesher inserting in random order, say) is
//! answered by the descent, seeded by its hint, as before the walk.
//!
//! **Cost.** A scattered point set pays a thread-local read, one distance
//! test against the record (no read of the grid) and a store of the new
//! record from the answer's corners, which the search has just read, until
//! the back-off sets it aside. (Carrying the answer's BVH slot out of the
//! search, to skip the one lookup of triangle → slot, was tried: no
//! difference beyond noise.) Measured in one process against queries that
//! neither read nor leave a record: 0.93–1.02 of their speed near the
//! surface and uniform in the box, dense and simplified grids, in one run
//! (0.89–1.06 in reruns on dense grids, where the record-free queries
//! themselves moved by up to 25 %; README, "Back-off for points in random
//! order"). A coherent set answers
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

/// Misses of the walk in a row on one grid, and the queries still to be
/// answered without it (see the module doc's back-off).
#[derive(Clone, Copy, Default)]
struct Misses {
    /// Id of the grid they were counted on.
    grid: u64,
    /// Misses in a row.
    count: u8,
    /// Queries still to be answered without a walk.
    skip: u8,
}

impl Misses {
    /// The count for `grid`: this one, or a fresh one for another grid.
    fn on(self, grid: u64) -> Misses {
        if self.grid == grid {
            self
        } else {
            Misses {
                grid,
                ..Misses::default()
            }
        }
    }

    /// Whether the next query may walk: not while set aside, and then the
    /// query uses up one skip.
    fn take(&mut self) -> bool {
        let walk = self.skip == 0;
        self.skip = self.skip.saturating_sub(1);
        walk
    }

    /// Counts a walk that helped (certified its answer or ended on it:
    /// `true`, the count clears) or missed (one more, and the back-off
    /// that follows).
    fn count(&mut self, helped: bool) {
        if helped {
            (self.count, self.skip) = (0, 0);
        } else {
            self.count = self.count.saturating_add(1);
            self.skip = backoff(self.count);
        }
    }
}

/// The last plain answer of this thread (see the module doc).
#[derive(Clone, Copy)]
struct Recent {
    /// The answer's triangle.
    triangle: u32,
    /// Its first corner in the BVH's corner order (the walk's anchor).
    anchor: [f64; 3],
    /// Squared radius around `anchor` within which the walk is tried.
    reach2: f64,
    /// The walk's misses from records on this grid (whose id it holds).
    misses: Misses,
}

thread_local! {
    static RECENT: Cell<Option<Recent>> = const { Cell::new(None) };
    /// The walk's misses from the caller's own hints.
    static HINTED: Cell<Misses> = const {
        Cell::new(Misses { grid: 0, count: 0, skip: 0 })
    };
}

/// Misses in a row tolerated before the walk is set aside.
const TOLERATED_MISSES: u8 = 3;
/// Most queries answered without a walk after a run of misses (the
/// back-off's cap).
const MAX_SKIP: u8 = 64;

/// Queries to answer without a walk after `misses` misses in a row: none
/// up to [`TOLERATED_MISSES`] − 1, then 1, 2, 4, … up to [`MAX_SKIP`]. O(1).
fn backoff(misses: u8) -> u8 {
    match misses.checked_sub(TOLERATED_MISSES) {
        None => 0,
        Some(k) if k < 7 => (1u8 << k).min(MAX_SKIP),
        Some(_) => MAX_SKIP,
    }
}

/// Source of grid ids (0 is never drawn).
static NEXT_GRID_ID: AtomicU64 = AtomicU64::new(1);

/// A new grid id, distinct from every other drawn in this process. O(1).
pub(crate) fn new_grid_id() -> u64 {
    NEXT_GRID_ID.fetch_add(1, Ordering::Relaxed)
}

/// The thread's last plain answer on grid `grid` as a hint for `p`, if `p`
/// lies within its reach and the record is not set aside (a point out of
/// reach counts as a miss). O(1); reads no grid memory.
pub(crate) fn hint_for(grid: u64, p: &[f64; 3]) -> Option<u32> {
    RECENT
        .try_with(|cell| {
            let mut r = cell.get()?;
            if r.misses.grid != grid {
                return None;
            }
            if !r.misses.take() {
                cell.set(Some(r));
                return None;
            }
            let d2: f64 = (0..3).map(|k| (p[k] - r.anchor[k]).powi(2)).sum();
            if d2 <= r.reach2 {
                return Some(r.triangle);
            }
            // Out of reach counts as a miss: a scattered point set soon
            // stops paying for the record.
            r.misses.count(false);
            cell.set(Some(r));
            None
        })
        .ok()
        .flatten()
}

/// Records `triangle` (an answer on grid `grid`, searched in `bvh`) as the
/// thread's last plain answer; `walked` says whether a walk from the last
/// record helped (`Some(true)`: it certified the answer or ended on it),
/// missed (`Some(false)`) or was not tried. While the record is set aside it is left as it is, and refreshed
/// by the last query that skips it. O(1): the answer's corners were just
/// read by the search.
pub(crate) fn remember(grid: u64, bvh: &Bvh, triangle: u32, walked: Option<bool>) {
    let Some(&slot) = bvh.triangle_prim.get(triangle as usize) else {
        return;
    };
    let c = &bvh.prim_corners[slot as usize];
    // During the thread's teardown there is no record to keep: nothing lost.
    let _ = RECENT.try_with(|cell| {
        let mut misses = match cell.get() {
            Some(r) if r.misses.grid == grid && r.misses.skip > 0 && walked.is_none() => return,
            Some(r) => r.misses.on(grid),
            None => Misses::default().on(grid),
        };
        if let Some(helped) = walked {
            misses.count(helped);
        }
        cell.set(Some(Recent {
            triangle,
            anchor: c[0],
            reach2: walk_reach2(c),
            misses,
        }));
    });
}

/// Whether a query on grid `grid` with the caller's own hint may walk from
/// it: not while the walks from the caller's hints are set aside (the
/// query then consumes one skip). O(1).
pub(crate) fn may_walk_from_hint(grid: u64) -> bool {
    HINTED
        .try_with(|cell| {
            let mut m = cell.get().on(grid);
            let walk = m.take();
            cell.set(m);
            walk
        })
        .unwrap_or(true)
}

/// Counts a walk from the caller's own hint on grid `grid`: helped
/// (`true`: it certified the answer or ended on it) or missed. O(1).
pub(crate) fn walked_from_hint(grid: u64, helped: bool) {
    let _ = HINTED.try_with(|cell| {
        let mut m = cell.get().on(grid);
        m.count(helped);
        cell.set(m);
    });
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
        // Points in random order, near and far (the back-off in every
        // state), then the walk again.
        let mut s = 9;
        let scattered = (0..600).map(|_| {
            let z = 0.6 * rng(&mut s) - 0.3;
            [1.4 * rng(&mut s) - 0.2, 1.4 * rng(&mut s) - 0.2, z]
        });
        for (i, p) in scattered.chain(walk(500, 6)).enumerate() {
            let plain = a.closest(p, None).unwrap();
            let fresh = a.closest(p, Some(u32::MAX)).unwrap();
            assert_eq!(bits(&plain), bits(&fresh), "point {i} {p:?}");
        }
    }

    #[test]
    fn the_back_off_doubles_from_the_third_miss_up_to_its_cap() {
        let skips: Vec<u8> = (0..12).map(backoff).collect();
        assert_eq!(skips, [0, 0, 0, 1, 2, 4, 8, 16, 32, 64, 64, 64]);
        assert_eq!(backoff(u8::MAX), MAX_SKIP);
        let mut m = Misses::default().on(7);
        for _ in 0..3 {
            m.count(false);
        }
        assert_eq!((m.count, m.skip), (3, 1));
        assert_eq!((m.on(7).skip, m.on(8).skip, m.on(8).grid), (1, 0, 8));
        m.count(true);
        assert_eq!((m.count, m.skip), (0, 0));
    }

    /// Three points in a row beyond the record's reach set the record aside
    /// for the next plain query; a certified walk clears the count.
    #[test]
    fn scattered_points_set_the_record_aside_and_a_walk_takes_it_back() {
        let a = wavy();
        let c = [
            [0.1, 0.1, 0.0],
            [0.9, 0.1, 0.0],
            [0.9, 0.9, 0.0],
            [0.1, 0.9, 0.0],
        ];
        // The first sets the record; the next three are out of its reach
        // (the third miss sets it aside, still anchored at c[2]'s answer).
        for &p in &c {
            a.closest(p, None).unwrap();
        }
        let at = a.closest(c[2], Some(u32::MAX)).unwrap();
        assert_eq!(hint_for(a.id(), &c[2]), None, "set aside for one query");
        assert_eq!(hint_for(a.id(), &c[2]), Some(at.triangle), "then back");
        // A point deep in the record's triangle, on it: a certified walk.
        let t = a.triangles()[at.triangle as usize].map(|v| a.vertices()[v as usize]);
        let centroid = std::array::from_fn(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
        assert_eq!(a.closest(centroid, None).unwrap().triangle, at.triangle);
        // Two misses after it do not set the record aside (five would).
        for &p in &c[..2] {
            a.closest(p, None).unwrap();
        }
        let at = a.closest(c[1], Some(u32::MAX)).unwrap();
        assert_eq!(hint_for(a.id(), &c[1]), Some(at.triangle), "misses cleared");
    }

    /// The caller's hints: three walks in a row from hints far from their
    /// points set the walk aside for the next hinted query, with the same
    /// answers; a certified walk clears the count.
    #[test]
    fn hints_that_keep_missing_are_set_aside_too() {
        let a = wavy();
        let (p, q) = ([0.1, 0.1, 0.0], [0.9, 0.9, 0.0]);
        let (tp, tq) = (a.closest(p, None).unwrap(), a.closest(q, None).unwrap());
        for _ in 0..3 {
            // Each hint lies across the sheet from its point: the walk bails
            // out and the descent finds another triangle (a miss).
            assert_eq!(bits(&a.closest(p, Some(tq.triangle)).unwrap()), bits(&tp));
        }
        assert!(!may_walk_from_hint(a.id()), "set aside for one query");
        assert!(may_walk_from_hint(a.id()), "then back");
        // A certified walk from the answer's own triangle clears the count.
        let t = a.triangles()[tp.triangle as usize].map(|v| a.vertices()[v as usize]);
        let centroid = std::array::from_fn(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
        a.closest(centroid, Some(tp.triangle)).unwrap();
        for _ in 0..2 {
            a.closest(p, Some(tq.triangle)).unwrap();
        }
        assert!(may_walk_from_hint(a.id()), "misses cleared");
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
