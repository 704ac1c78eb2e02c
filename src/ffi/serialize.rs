//! A grid to bytes and back (`.abgs`, see [`crate::io::abgs_bin`]), for
//! sending a grid between processes (MPI) or keeping it in memory.

use super::boundary::*;
use super::grid::abgs_grid;
use crate::io::abgs_bin;
use std::ffi::c_void;

/// Serialises `grid` into the caller's buffer `buf` of `capacity` bytes:
/// vertices, triangles, sizes, other per-vertex arrays, the input report and
/// the BVH layout, with a format version, a byte-order marker and a CRC-32
/// (the `.abgs` format; `abgs_grid_save` writes the same bytes to a `.abgs`
/// file). `*out_len` receives the bytes needed — also when the buffer is too
/// small, and alone when `buf` is NULL with `capacity` 0, so a caller asks
/// first, allocates, then calls again:
///
/// ```c
/// size_t n = 0;
/// abgs_grid_serialize(g, NULL, 0, &n);
/// void *buf = malloc(n);
/// abgs_grid_serialize(g, buf, n, &n);
/// ```
///
/// Errors: NULL (grid, out_len, or buf with capacity > 0), BUFFER_TOO_SMALL
/// (nothing written to `buf`), BUSY (a mutation is running on the grid).
/// O(V + F); the bytes depend only on the grid.
///
/// # Safety
/// `grid` is NULL or a live grid from this library; `buf` is NULL or holds
/// `capacity` writable bytes; `out_len` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_serialize(
    grid: *const abgs_grid,
    buf: *mut c_void,
    capacity: usize,
    out_len: *mut usize,
) -> abgs_status {
    guard("abgs_grid_serialize", || {
        // SAFETY: a grid from this library or NULL (checked).
        let g = unsafe { req(grid, "grid")? }.read()?;
        // SAFETY: writable or NULL (checked).
        let len = unsafe { out(out_len, "out_len")? };
        let needed = abgs_bin::encoded_len(&g, true);
        *len = needed;
        if buf.is_null() {
            if capacity == 0 {
                return Ok(());
            }
            return err(abgs_status::ABGS_ERR_NULL, "buf is NULL");
        }
        if capacity < needed {
            return err(
                abgs_status::ABGS_ERR_BUFFER_TOO_SMALL,
                format!("buf holds {capacity} bytes, {needed} needed"),
            );
        }
        // SAFETY: non-NULL with `capacity` >= needed writable bytes by contract.
        let dst = unsafe { slice_mut(buf as *mut u8, needed, "buf")? };
        *len = abgs_bin::encode_into(&g, dst)?;
        Ok(())
    })
}

/// Builds a grid from `len` bytes at `buf` written by `abgs_grid_serialize`
/// (or read from a `.abgs` file); the bytes are only read (the caller keeps
/// them, and may free them once the call returns). Everything is checked before use: the length, magic, format
/// version, byte order and CRC-32 first, then the counts against the length
/// (before anything is allocated), then the content as
/// `abgs_grid_from_arrays` checks it (coordinates, indices, sizes) and the
/// stored BVH layout. The grid answers every query bit for bit as the one
/// serialised. On success `*out_grid` owns a new grid; on failure it is NULL.
/// O(V + F log F) (the adjacency is rebuilt).
///
/// Errors: NULL (buf, out_grid), PARSE (truncated, corrupt, checksum
/// mismatch, counts that disagree with the length, not an abgs buffer), UNSUPPORTED_FORMAT (another format version, big-endian),
/// NON_FINITE, OUT_OF_RANGE, INVALID_SIZE, EMPTY, INVALID_ARGUMENT (a
/// degenerate triangle, an inconsistent report or BVH layout).
///
/// # Safety
/// `buf` is NULL or holds `len` readable bytes; `out_grid` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn abgs_grid_deserialize(
    buf: *const c_void,
    len: usize,
    out_grid: *mut *mut abgs_grid,
) -> abgs_status {
    guard("abgs_grid_deserialize", || {
        // SAFETY: writable or NULL (checked).
        let o = unsafe { out(out_grid, "out_grid")? };
        *o = std::ptr::null_mut();
        if buf.is_null() {
            return err(abgs_status::ABGS_ERR_NULL, "buf is NULL");
        }
        // SAFETY: `len` readable bytes at a non-NULL `buf` by contract.
        let bytes = unsafe { slice(buf as *const u8, len, "buf")? };
        *o = abgs_grid::boxed(abgs_bin::decode(bytes)?);
        Ok(())
    })
}
