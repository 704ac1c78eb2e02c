//! Size queries through the C ABI. All are const and thread-safe.

use super::boundary::*;
use super::grid::abgs_grid;
use super::versioned::{check_out, versioned, write_out};

/// Answer of `abgs_query_closest`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_hit {
    /// `sizeof(abgs_hit)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Triangle holding the closest point.
    pub triangle: u32,
    /// Barycentric coordinates on that triangle.
    pub bary: [f64; 3],
    /// The closest point.
    pub point: [f64; 3],
    /// Distance to the surface.
    pub distance: f64,
    /// Interpolated size, with the tie rule between bodies of
    /// `abgs_query_size` (NaN when the grid has no sizes).
    pub size: f64,
}

versioned!(abgs_hit, 72);

/// Size at `point` (3 doubles): exact closest point on the grid, barycentric
/// interpolation there. Expected O(log F).
///
/// Queries along a front need no hint: each thread remembers its last plain
/// answer (one, on the grid it was given on), and a point within a few
/// triangles of it is answered by the certified walk of `abgs_query_size_hinted` (the
/// first such query builds its table). The answer is the same bit for bit,
/// whatever the thread asked before. Points in random order stop using it:
/// after three misses in a row the thread sets its record aside for 1, 2,
/// 4, … up to 64 queries.
///
/// Ties between bodies: where bodies of an assembly touch, a point whose
/// closest point `q` on the grid has another body's face within the contact
/// gap `c` (diagonal / 2000) of `q` gets the smallest of those bodies' sizes,
/// each interpolated at that body's closest point to `q` (at most 4 bodies),
/// at any distance from the surface: every point whose closest point lies on
/// a contact reads one agreed size. Bodies farther apart than `c` are never
/// mixed. The same rule holds for hinted and batch queries; volume queries
/// (a minimum over the surface) satisfy it by construction.
/// Errors: NULL, NON_FINITE, NO_SIZES, BUSY (a mutation is running).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_size(
    grid: *const abgs_grid,
    point: *const f64,
    out_size: *mut f64,
) -> abgs_status {
    guard("abgs_query_size", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: three doubles or NULL (checked).
        let p = unsafe { point3(point, "point")? };
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_size, "out_size")? };
        *o = g.query_size(p)?;
        Ok(())
    })
}

/// As `abgs_query_size`, seeded by `*hint` (a triangle index from an earlier
/// query, or `ABGS_NO_HINT`; any value is safe) and updating it to the triangle
/// of this answer. The size equals `abgs_query_size`'s bit for bit; only the time
/// changes: a point near the surface a few triangles from its hint (as an
/// advancing front queries) is answered by a certified walk without a tree
/// descent. The grid's first hinted query builds the table that walk reads
/// (O(F log F), parallel, 16 bytes per triangle). Hints chained through
/// points in random order are set aside as the plain record is (three
/// misses in a row; counted apart): their queries descend the tree, seeded
/// by the hint.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_size_hinted(
    grid: *const abgs_grid,
    point: *const f64,
    hint: *mut u32,
    out_size: *mut f64,
) -> abgs_status {
    guard("abgs_query_size_hinted", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: three doubles or NULL (checked).
        let p = unsafe { point3(point, "point")? };
        disjoint(&[
            (hint as *const u8, 4, "hint"),
            (out_size as *const u8, 8, "out_size"),
        ])?;
        // SAFETY: writable or NULL (checked).
        let h = unsafe { out(hint, "hint")? };
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_size, "out_size")? };
        *o = g.query_size_hinted(p, h)?;
        Ok(())
    })
}

/// Sizes at `n` points (`points`: 3n doubles) into `out_sizes` (n doubles),
/// in parallel on the rayon thread pool (`RAYON_NUM_THREADS` sets its size).
/// Results equal the single queries', whatever the thread count. A scattered
/// batch (1,024 points or more whose consecutive points lie farther apart than
/// 1/100 of the batch's box diagonal on average) is answered along a Morton
/// curve for warmer caches, in about half the time for random points, with up
/// to 20 bytes per point of scratch memory; `out_sizes[i]` still answers point
/// `i`, bit for bit. All points are
/// checked first: on error nothing is written. `points` and `out_sizes` must not
/// overlap.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_sizes(
    grid: *const abgs_grid,
    points: *const f64,
    n: usize,
    out_sizes: *mut f64,
) -> abgs_status {
    guard("abgs_query_sizes", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: the caller guarantees n points and n outputs.
        let (p, o) = unsafe { batch_args(points, n, out_sizes)? };
        g.query_sizes(p, o)?;
        Ok(())
    })
}

/// Volume-mode size at `point`: `H(x) = min over surface points y of
/// h(y) + ln(beta)·|x − y|`, the size a volume mesher should use inside the
/// domain with gradation ratio `beta` (> 1, e.g. 1.2). Exact, by branch and bound.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_size_volume(
    grid: *const abgs_grid,
    point: *const f64,
    beta: f64,
    out_size: *mut f64,
) -> abgs_status {
    guard("abgs_query_size_volume", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: three doubles or NULL (checked).
        let p = unsafe { point3(point, "point")? };
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_size, "out_size")? };
        if !beta.is_finite() {
            return err(abgs_status::ABGS_ERR_NON_FINITE, format!("beta = {beta}"));
        }
        *o = g.query_volume(p, beta)?.size;
        Ok(())
    })
}

/// Batch of volume-mode queries, in parallel, a scattered batch along a Morton
/// curve (see `abgs_query_sizes`: the same answers as single queries; the buffers
/// must not overlap).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_sizes_volume(
    grid: *const abgs_grid,
    points: *const f64,
    n: usize,
    beta: f64,
    out_sizes: *mut f64,
) -> abgs_status {
    guard("abgs_query_sizes_volume", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: the caller guarantees n points and n outputs.
        let (p, o) = unsafe { batch_args(points, n, out_sizes)? };
        if !beta.is_finite() {
            return err(abgs_status::ABGS_ERR_NON_FINITE, format!("beta = {beta}"));
        }
        g.query_sizes_volume(p, beta, o)?;
        Ok(())
    })
}

/// Closest point, triangle, barycentric coordinates, distance and size at
/// `point`; `hint` is a triangle index or `ABGS_NO_HINT`. Works without sizes
/// (size is then NaN).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_query_closest(
    grid: *const abgs_grid,
    point: *const f64,
    hint: u32,
    out_hit: *mut abgs_hit,
) -> abgs_status {
    guard("abgs_query_closest", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: three doubles or NULL (checked).
        let p = unsafe { point3(point, "point")? };
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_hit, "out_hit", false)? };
        let h = g.closest(p, (hint != ABGS_NO_HINT).then_some(hint))?;
        let hit = abgs_hit {
            struct_size: 0,
            triangle: h.triangle,
            bary: h.bary,
            point: h.point,
            distance: h.distance,
            size: h.size,
        };
        // SAFETY: checked above.
        unsafe { write_out(out_hit, &hit, "out_hit") }
    })
}

/// Views the batch arguments.
///
/// # Safety
/// `points` must hold 3n doubles and `out_sizes` n writable doubles (or be NULL).
unsafe fn batch_args<'a>(
    points: *const f64,
    n: usize,
    out_sizes: *mut f64,
) -> FfiResult<(&'a [[f64; 3]], &'a mut [f64])> {
    if n > 0 && (points.is_null() || out_sizes.is_null()) {
        return err(abgs_status::ABGS_ERR_NULL, "points or out_sizes is NULL");
    }
    disjoint(&[
        (points as *const u8, n.saturating_mul(24), "points"),
        (out_sizes as *const u8, n.saturating_mul(8), "out_sizes"),
    ])?;
    // SAFETY: [f64; 3] has the layout and alignment of three doubles; n points by contract.
    let p = unsafe { slice(points as *const [f64; 3], n, "points")? };
    // SAFETY: n writable doubles by contract.
    let o = unsafe { slice_mut(out_sizes, n, "out_sizes")? };
    Ok((p, o))
}
