//! The grid handle, `abgs_grid`: one reader–writer lock around the grid and
//! whatever the call that made it left beside it (its *provenance*).
//!
//! The provenance is type-erased (`Box<dyn Any>`), so each algorithm's C
//! module stores and reads its own record — the remesher its kept feature
//! edges and issues, the simplifier its iteration records — and this module
//! knows none of them. It lives inside the lock, so no call can read it
//! without holding the grid, and a concurrent `abgs_grid_free` sees the call.
//!
//! Concurrency: const calls take the read side with `try_read`, mutating calls
//! (`abgs_grid_set_sizes`, `abgs_compute_size`, …) and [`abgs_grid::destroy`]
//! the write side with `try_write`; neither ever waits, a conflict is
//! `ABGS_ERR_BUSY`. `destroy` keeps the write side until the memory is gone,
//! so a call that starts while it runs gets BUSY instead of reading freed
//! memory. A call that starts after `abgs_grid_free` returned is the caller's
//! use-after-free, as with `free()`.

use super::boundary::*;
use crate::mesh::Grid;
use std::any::Any;
use std::ops::{Deref, DerefMut};
use std::sync::{RwLock, RwLockReadGuard, RwLockWriteGuard, TryLockError};

/// Opaque handle to a background grid. Create with `abgs_grid_from_arrays`,
/// `abgs_grid_load`, `abgs_grid_remesh` or `abgs_simplify`, release with
/// `abgs_grid_free`.
pub struct abgs_grid {
    lock: RwLock<Held>,
}

/// What the lock holds: the grid and its provenance.
pub(crate) struct Held {
    grid: Grid,
    provenance: Option<Box<dyn Any + Send + Sync>>,
}

impl Held {
    /// The record of type `T` left by the call that made the grid, if that
    /// call left one of this type.
    pub(crate) fn provenance<T: Any>(&self) -> Option<&T> {
        self.provenance.as_ref()?.downcast_ref()
    }
}

impl Deref for Held {
    type Target = Grid;
    fn deref(&self) -> &Grid {
        &self.grid
    }
}

impl DerefMut for Held {
    fn deref_mut(&mut self) -> &mut Grid {
        &mut self.grid
    }
}

impl abgs_grid {
    /// A new handle owning `grid`, with no provenance.
    pub(crate) fn boxed(grid: Grid) -> *mut abgs_grid {
        Self::boxed_from(grid, None)
    }

    /// A new handle owning `grid` and the record of the call that made it.
    pub(crate) fn boxed_with<T: Any + Send + Sync>(grid: Grid, record: T) -> *mut abgs_grid {
        Self::boxed_from(grid, Some(Box::new(record)))
    }

    fn boxed_from(grid: Grid, provenance: Option<Box<dyn Any + Send + Sync>>) -> *mut abgs_grid {
        Box::into_raw(Box::new(abgs_grid {
            lock: RwLock::new(Held { grid, provenance }),
        }))
    }

    /// Shared access for const calls; BUSY while a mutation (or a free) runs.
    pub(crate) fn read(&self) -> FfiResult<RwLockReadGuard<'_, Held>> {
        match self.lock.try_read() {
            Ok(g) => Ok(g),
            Err(TryLockError::WouldBlock) => err(
                abgs_status::ABGS_ERR_BUSY,
                "the grid is being modified or freed by another call",
            ),
            Err(TryLockError::Poisoned(_)) => poisoned(),
        }
    }

    /// Exclusive access for mutating calls; BUSY while any other call uses the grid.
    pub(crate) fn write(&self) -> FfiResult<RwLockWriteGuard<'_, Held>> {
        match self.lock.try_write() {
            Ok(g) => Ok(g),
            Err(TryLockError::WouldBlock) => err(
                abgs_status::ABGS_ERR_BUSY,
                "the grid is in use by another call",
            ),
            Err(TryLockError::Poisoned(_)) => poisoned(),
        }
    }

    /// Frees a handle made by this module, unless another call holds it
    /// (BUSY, nothing freed). A poisoned grid (an earlier internal error) is
    /// freed all the same.
    ///
    /// # Safety
    /// `grid` is non-NULL, came from [`abgs_grid::boxed`] or
    /// [`abgs_grid::boxed_with`], and was not freed before.
    pub(crate) unsafe fn destroy(grid: *mut abgs_grid) -> FfiResult<()> {
        // SAFETY: a live handle by the caller's contract.
        let h = unsafe { &*grid };
        let guard = match h.lock.try_write() {
            Ok(g) => g,
            Err(TryLockError::Poisoned(p)) => p.into_inner(),
            Err(TryLockError::WouldBlock) => {
                return err(
                    abgs_status::ABGS_ERR_BUSY,
                    "the grid is in use by another call; nothing was freed",
                )
            }
        };
        // Keep the lock held while the memory goes: a call that starts now
        // meets a held lock (BUSY), never a released one over freed memory.
        // The lock itself owns no resource, so dropping it held is sound.
        std::mem::forget(guard);
        // SAFETY: the handle came from Box::into_raw and no call holds it
        // (the write side was acquired above); ownership returns to Rust.
        drop(unsafe { Box::from_raw(grid) });
        Ok(())
    }
}

fn poisoned<T>() -> FfiResult<T> {
    err(
        abgs_status::ABGS_ERR_INTERNAL,
        "the grid was left unusable by an earlier internal error",
    )
}
