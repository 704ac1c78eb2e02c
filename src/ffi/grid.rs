//! Grid lifecycle, I/O, sizes, statistics and copy-out accessors.

use super::boundary::*;
pub use super::handle::abgs_grid;
use super::versioned::{check_out, versioned, write_out};
use crate::mesh::{BuildOptions, Grid};
use std::ffi::c_char;

/// Counts, validation findings and extent of a grid (`abgs_grid_get_stats`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct abgs_grid_stats {
    /// `sizeof(abgs_grid_stats)`, set by the caller (the header's growth rule).
    pub struct_size: u32,
    /// Vertices.
    pub vertices: u64,
    /// Triangles.
    pub triangles: u64,
    /// Unique edges.
    pub edges: u64,
    /// Bodies (connected components through manifold edges).
    pub bodies: u64,
    /// Edges with one triangle.
    pub boundary_edges: u64,
    /// Edges with more than two triangles.
    pub non_manifold_edges: u64,
    /// Vertices whose triangles form several fans.
    pub non_manifold_vertices: u64,
    /// Triangles given on input.
    pub input_triangles: u64,
    /// Triangles dropped (repeated corner or zero area).
    pub dropped_triangles: u64,
    /// Vertices merged by welding.
    pub welded_vertices: u64,
    /// Triangles re-oriented.
    pub flipped_triangles: u64,
    /// 1 when the grid carries sizes.
    pub has_sizes: i32,
    /// Smallest size (0 without sizes).
    pub size_min: f64,
    /// Largest size (0 without sizes).
    pub size_max: f64,
    /// Bounding-box lower corner.
    pub bbox_min: [f64; 3],
    /// Bounding-box upper corner.
    pub bbox_max: [f64; 3],
    /// Bounding-box diagonal.
    pub diagonal: f64,
    /// Heap bytes held by the grid and its BVH (from its first size query
    /// on, with the BVH's 4-wide query view: 33–45 bytes per triangle more;
    /// from its first hinted or batch query on, with the hinted search's
    /// prism table: 16 bytes per triangle more).
    pub memory_bytes: u64,
}

versioned!(abgs_grid_stats, 184);

/// Builds a grid from caller arrays, which are copied (the caller keeps ownership).
///
/// `xyz`: `3 * n_vertices` doubles; `triangles`: `3 * n_triangles` 0-based vertex
/// indices; `sizes`: NULL or `n_vertices` values, each finite and > 0. Vertices
/// are neither welded nor reordered; zero-area triangles are dropped (see
/// `abgs_grid_stats.dropped_triangles`), and triangle orientation is made
/// consistent per body. On success `*out` owns a new grid. O(F log F).
///
/// Errors: NULL, NON_FINITE (a coordinate), OUT_OF_RANGE (an index),
/// INVALID_SIZE, EMPTY (no triangle left), INVALID_ARGUMENT (counts too large).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_from_arrays(
    xyz: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    sizes: *const f64,
    out_grid: *mut *mut abgs_grid,
) -> abgs_status {
    guard("abgs_grid_from_arrays", || {
        // SAFETY: the caller passes a writable pointer or NULL (checked).
        let o = unsafe { out(out_grid, "out_grid")? };
        *o = std::ptr::null_mut();
        if n_vertices > u32::MAX as usize {
            return err(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                "more than 2^32-1 vertices",
            );
        }
        let nv3 = n_vertices.checked_mul(3).ok_or_else(|| {
            FfiError(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                "n_vertices too large".into(),
            )
        })?;
        let nt3 = n_triangles.checked_mul(3).ok_or_else(|| {
            FfiError(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                "n_triangles too large".into(),
            )
        })?;
        if n_vertices == 0 || n_triangles == 0 {
            return err(
                abgs_status::ABGS_ERR_EMPTY,
                format!("{n_vertices} vertices and {n_triangles} triangles given"),
            );
        }
        // SAFETY: the caller guarantees 3*n_vertices doubles at xyz.
        let v = unsafe { slice(xyz, nv3, "xyz")? };
        // SAFETY: the caller guarantees 3*n_triangles indices at triangles.
        let t = unsafe { slice(triangles, nt3, "triangles")? };
        let s = if sizes.is_null() {
            None
        } else {
            // SAFETY: non-NULL sizes holds n_vertices doubles by contract.
            Some(unsafe { slice(sizes, n_vertices, "sizes")? }.to_vec())
        };
        let verts = v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let tris = t.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let g = Grid::from_arrays(verts, tris, s, &BuildOptions::default())?;
        *o = abgs_grid::boxed(g);
        Ok(())
    })
}

/// Loads a grid from a file, format by extension (stl, obj, off, ply, msh, vtk,
/// vtu, mesh, abgs). STL is welded (tolerance 1e-7 of the diagonal); a per-vertex
/// array named `size` becomes the sizes. An `.abgs` file (`abgs_grid_save`'s
/// binary form, the bytes of `abgs_grid_serialize`) gives the saved grid back
/// bit for bit, BVH included, checked as `abgs_grid_deserialize` checks it.
///
/// Errors: NULL, IO, PARSE, UNSUPPORTED_FORMAT, NON_FINITE, OUT_OF_RANGE,
/// INVALID_SIZE, EMPTY (and INVALID_ARGUMENT for an inconsistent `.abgs`).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_load(
    path: *const c_char,
    out_grid: *mut *mut abgs_grid,
) -> abgs_status {
    guard("abgs_grid_load", || {
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_grid, "out_grid")? };
        *o = std::ptr::null_mut();
        // SAFETY: NUL-terminated or NULL (checked).
        let p = unsafe { super::boundary::path(path)? };
        *o = abgs_grid::boxed(Grid::load(p)?);
        Ok(())
    })
}

/// Writes the grid (with sizes as point data `size`) to a file, format by
/// extension: vtk (ParaView), msh (Gmsh background field), mesh (+ .sol for
/// MMG), vtu, ply, obj, off, stl, or abgs (the whole grid in binary, fastest
/// to load: the bytes of `abgs_grid_serialize`).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_save(
    grid: *const abgs_grid,
    path: *const c_char,
) -> abgs_status {
    guard("abgs_grid_save", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: NUL-terminated or NULL (checked).
        let p = unsafe { super::boundary::path(path)? };
        g.save(p)?;
        Ok(())
    })
}

/// Replaces the sizes: `n` must equal the vertex count, each value finite and > 0.
/// Returns BUSY if another call is using the grid. O(V + F).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_set_sizes(
    grid: *mut abgs_grid,
    sizes: *const f64,
    n: usize,
) -> abgs_status {
    guard("abgs_grid_set_sizes", || {
        // SAFETY: a grid from this library or NULL (checked).
        let h = unsafe { req(grid as *const abgs_grid, "grid")? };
        if sizes.is_null() {
            return err(abgs_status::ABGS_ERR_NULL, "sizes is NULL");
        }
        let mut g = h.write()?;
        // The count is checked before anything is read, so a wrong count
        // never makes the library read past the caller's array.
        let nv = g.vertices().len();
        if n != nv {
            return err(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                format!("{n} sizes given for {nv} vertices"),
            );
        }
        // SAFETY: the caller guarantees n doubles at sizes.
        let s = unsafe { slice(sizes, n, "sizes")? }.to_vec();
        g.set_sizes(s)?;
        Ok(())
    })
}

/// Fills `*out_stats`. O(V) (size range).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_get_stats(
    grid: *const abgs_grid,
    out_stats: *mut abgs_grid_stats,
) -> abgs_status {
    guard("abgs_grid_get_stats", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: NULL (reported) or `struct_size` writable bytes.
        unsafe { check_out(out_stats, "out_stats", false)? };
        let st = g.stats();
        let r = g.report();
        let b = g.bbox();
        let (lo, hi) = g.sizes().map_or((0.0, 0.0), |s| {
            s.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                })
        });
        let stats = abgs_grid_stats {
            struct_size: 0,
            vertices: st.vertices as u64,
            triangles: st.triangles as u64,
            edges: st.edges as u64,
            bodies: st.bodies as u64,
            boundary_edges: r.boundary_edges as u64,
            non_manifold_edges: r.non_manifold_edges as u64,
            non_manifold_vertices: r.non_manifold_vertices as u64,
            input_triangles: r.input_triangles as u64,
            dropped_triangles: (r.dropped_repeated_index + r.dropped_zero_area) as u64,
            welded_vertices: r.welded_vertices as u64,
            flipped_triangles: r.flipped_triangles as u64,
            has_sizes: g.sizes().is_some() as i32,
            size_min: lo,
            size_max: hi,
            bbox_min: b.min,
            bbox_max: b.max,
            diagonal: b.diagonal(),
            memory_bytes: (st.grid_bytes + st.bvh_bytes) as u64,
        };
        // SAFETY: checked above.
        unsafe { write_out(out_stats, &stats, "out_stats") }
    })
}

/// Number of vertices into `*out_count`.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_vertex_count(
    grid: *const abgs_grid,
    out_count: *mut usize,
) -> abgs_status {
    guard("abgs_grid_vertex_count", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: writable or NULL (checked).
        *unsafe { out(out_count, "out_count")? } = g.vertices().len();
        Ok(())
    })
}

/// Number of triangles into `*out_count`.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_triangle_count(
    grid: *const abgs_grid,
    out_count: *mut usize,
) -> abgs_status {
    guard("abgs_grid_triangle_count", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: writable or NULL (checked).
        *unsafe { out(out_count, "out_count")? } = g.triangles().len();
        Ok(())
    })
}

/// Copies the vertex coordinates (x0 y0 z0 x1 ...) into `out_xyz`, which holds
/// `capacity` doubles (at least 3 × vertex count, else BUFFER_TOO_SMALL).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_copy_vertices(
    grid: *const abgs_grid,
    out_xyz: *mut f64,
    capacity: usize,
) -> abgs_status {
    guard("abgs_grid_copy_vertices", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let flat = g.vertices().as_flattened();
        // SAFETY: the caller guarantees `capacity` writable doubles.
        copy_out(flat, unsafe {
            checked_out(out_xyz, capacity, flat.len(), "out_xyz")?
        });
        Ok(())
    })
}

/// Copies the triangles (3 indices each) into `out_triangles`, which holds
/// `capacity` indices (at least 3 × triangle count).
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_copy_triangles(
    grid: *const abgs_grid,
    out_triangles: *mut u32,
    capacity: usize,
) -> abgs_status {
    guard("abgs_grid_copy_triangles", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let flat = g.triangles().as_flattened();
        // SAFETY: the caller guarantees `capacity` writable indices.
        copy_out(flat, unsafe {
            checked_out(out_triangles, capacity, flat.len(), "out_triangles")?
        });
        Ok(())
    })
}

/// Copies the sizes (one per vertex) into `out_sizes` (`capacity` ≥ vertex count).
/// NO_SIZES when the grid has none.
///
/// # Safety
/// Each pointer is NULL (reported as ABGS_ERR_NULL) or valid for the stated
/// number of elements; a grid pointer comes from this library and is not freed.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_copy_sizes(
    grid: *const abgs_grid,
    out_sizes: *mut f64,
    capacity: usize,
) -> abgs_status {
    guard("abgs_grid_copy_sizes", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        let s = g.sizes().ok_or(crate::Error::NoSizes)?;
        // SAFETY: the caller guarantees `capacity` writable doubles.
        copy_out(s, unsafe {
            checked_out(out_sizes, capacity, s.len(), "out_sizes")?
        });
        Ok(())
    })
}

/// Releases a grid. NULL is accepted and ignored. Returns BUSY (and frees
/// nothing) while another call is using the grid; a call that starts while
/// this one runs gets BUSY too. As with `free`, no call may start on the grid
/// once this one has returned OK.
///
/// # Safety
/// `grid` is NULL or a grid from this library that was not freed before.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_free(grid: *mut abgs_grid) -> abgs_status {
    guard("abgs_grid_free", || {
        if grid.is_null() {
            return Ok(());
        }
        // SAFETY: a live grid from this library by the caller's contract.
        unsafe { abgs_grid::destroy(grid) }
    })
}

/// Checks a caller output buffer of `capacity` items for `needed` items.
///
/// # Safety
/// A non-NULL `p` must point to `capacity` writable items.
pub(crate) unsafe fn checked_out<'a, T>(
    p: *mut T,
    capacity: usize,
    needed: usize,
    what: &str,
) -> FfiResult<&'a mut [T]> {
    if p.is_null() {
        return err(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL"));
    }
    if capacity < needed {
        return err(
            abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
            format!("{what} holds {capacity} items, {needed} needed"),
        );
    }
    // SAFETY: forwarded contract; only the first `needed` items are viewed.
    unsafe { slice_mut(p, needed, what) }
}

fn copy_out<T: Copy>(src: &[T], dst: &mut [T]) {
    dst.copy_from_slice(src);
}
