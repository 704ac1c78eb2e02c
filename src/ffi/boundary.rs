//! Status codes, the thread-local error message, the panic boundary and the
//! pointer-checking helpers shared by every export.

use crate::error::Error;
use std::cell::RefCell;
use std::ffi::{c_char, c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Major version of the library (the header's and [`abgs_version_number`]'s).
pub const ABGS_VERSION_MAJOR: u32 = 0;
/// Minor version.
pub const ABGS_VERSION_MINOR: u32 = 1;
/// Patch version.
pub const ABGS_VERSION_PATCH: u32 = 0;
/// Value of a hint that names no triangle.
pub const ABGS_NO_HINT: u32 = u32::MAX;

/// Result of every call. The numbers are stable across releases.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum abgs_status {
    /// Success.
    ABGS_OK = 0,
    /// A required pointer is NULL.
    ABGS_ERR_NULL = 1,
    /// An argument is malformed (counts, lengths, options).
    ABGS_ERR_INVALID_ARGUMENT = 2,
    /// An index is out of range (e.g. a triangle names a missing vertex).
    ABGS_ERR_OUT_OF_RANGE = 3,
    /// A coordinate or parameter is NaN or infinite.
    ABGS_ERR_NON_FINITE = 4,
    /// A size is not finite and > 0.
    ABGS_ERR_INVALID_SIZE = 5,
    /// A file could not be opened, read or written.
    ABGS_ERR_IO = 6,
    /// A file's content is malformed.
    ABGS_ERR_PARSE = 7,
    /// The file extension names no supported format.
    ABGS_ERR_UNSUPPORTED_FORMAT = 8,
    /// A caller buffer is too small.
    ABGS_ERR_BUFFER_TOO_SMALL = 9,
    /// The grid would have no triangles.
    ABGS_ERR_EMPTY = 10,
    /// The grid has no sizes yet.
    ABGS_ERR_NO_SIZES = 11,
    /// A mutating call met a grid in use by another call.
    ABGS_ERR_BUSY = 12,
    /// The caller's progress callback asked to stop.
    ABGS_ERR_CANCELLED = 13,
    /// The feature is not available in this build.
    ABGS_ERR_NOT_AVAILABLE = 14,
    /// A bug in abgs (a caught panic); the message says where.
    ABGS_ERR_INTERNAL = 99,
}

/// An error on its way to C: the status and the message.
pub(crate) struct FfiError(pub abgs_status, pub String);

impl From<Error> for FfiError {
    fn from(e: Error) -> Self {
        let st = match &e {
            Error::InvalidArgument(_) => abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            Error::OutOfRange(_) => abgs_status::ABGS_ERR_OUT_OF_RANGE,
            Error::NonFinite(_) => abgs_status::ABGS_ERR_NON_FINITE,
            Error::InvalidSize(_) => abgs_status::ABGS_ERR_INVALID_SIZE,
            Error::Io { .. } => abgs_status::ABGS_ERR_IO,
            Error::Parse { .. } => abgs_status::ABGS_ERR_PARSE,
            Error::UnsupportedFormat(_) => abgs_status::ABGS_ERR_UNSUPPORTED_FORMAT,
            Error::Empty(_) => abgs_status::ABGS_ERR_EMPTY,
            Error::NoSizes => abgs_status::ABGS_ERR_NO_SIZES,
        };
        FfiError(st, e.to_string())
    }
}

pub(crate) type FfiResult<T> = Result<T, FfiError>;

pub(crate) fn err<T>(status: abgs_status, msg: impl Into<String>) -> FfiResult<T> {
    Err(FfiError(status, msg.into()))
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(msg: &str) {
    let c = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Runs `f` behind the panic boundary and turns its outcome into a status,
/// recording the message of a failure for [`abgs_last_error_message`].
pub(crate) fn guard(name: &str, f: impl FnOnce() -> FfiResult<()>) -> abgs_status {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => abgs_status::ABGS_OK,
        Ok(Err(FfiError(st, msg))) => {
            set_last_error(&format!("{name}: {msg}"));
            st
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("{name}: internal error (please report): {what}"));
            abgs_status::ABGS_ERR_INTERNAL
        }
    }
}

/// Checks a pointer for NULL and returns a shared reference.
///
/// # Safety
/// A non-NULL `p` must point to a valid, live `T`.
pub(crate) unsafe fn req<'a, T>(p: *const T, what: &str) -> FfiResult<&'a T> {
    // SAFETY: the caller guarantees that a non-NULL `p` points to a live `T`.
    unsafe { p.as_ref() }
        .ok_or_else(|| FfiError(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL")))
}

/// Checks an out-pointer for NULL and returns a mutable reference.
///
/// # Safety
/// A non-NULL `p` must point to writable memory for one `T`.
pub(crate) unsafe fn out<'a, T>(p: *mut T, what: &str) -> FfiResult<&'a mut T> {
    // SAFETY: the caller guarantees that a non-NULL `p` is valid for writes of one `T`.
    unsafe { p.as_mut() }
        .ok_or_else(|| FfiError(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL")))
}

/// Views `len` items at `p` (NULL allowed when `len == 0`).
///
/// # Safety
/// A non-NULL `p` must point to `len` initialised, live items.
pub(crate) unsafe fn slice<'a, T>(p: *const T, len: usize, what: &str) -> FfiResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return err(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL"));
    }
    if !(p as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what} is misaligned"),
        );
    }
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what}: length {len} too large"),
        );
    }
    // SAFETY: non-NULL, aligned, size checked; the caller guarantees `len` live items.
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// Mutable view of `len` items at `p` (NULL allowed when `len == 0`).
///
/// # Safety
/// A non-NULL `p` must point to `len` writable items not aliased elsewhere.
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, len: usize, what: &str) -> FfiResult<&'a mut [T]> {
    // SAFETY: same contract as `slice`, plus exclusivity from the caller.
    let s = unsafe { slice(p as *const T, len, what)? };
    // SAFETY: `s` came from `p`, which the caller guarantees writable and unaliased.
    Ok(unsafe { std::slice::from_raw_parts_mut(s.as_ptr() as *mut T, s.len()) })
}

/// Reads three coordinates at `p`.
///
/// # Safety
/// A non-NULL `p` must point to three readable doubles.
pub(crate) unsafe fn point3(p: *const f64, what: &str) -> FfiResult<[f64; 3]> {
    // SAFETY: forwarded contract: three readable doubles.
    let s = unsafe { slice(p, 3, what)? };
    Ok([s[0], s[1], s[2]])
}

/// Reads a NUL-terminated path.
///
/// # Safety
/// A non-NULL `p` must point to a NUL-terminated string.
pub(crate) unsafe fn path<'a>(p: *const c_char) -> FfiResult<&'a std::path::Path> {
    if p.is_null() {
        return err(abgs_status::ABGS_ERR_NULL, "path is NULL");
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's contract.
    let bytes = unsafe { CStr::from_ptr(p) }.to_bytes();
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(std::path::Path::new(std::ffi::OsStr::from_bytes(bytes)))
    }
    #[cfg(not(unix))]
    {
        std::str::from_utf8(bytes)
            .map(std::path::Path::new)
            .map_err(|_| {
                FfiError(
                    abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                    "path is not UTF-8".into(),
                )
            })
    }
}

/// Text of the last failed call on this thread ("" if none failed yet).
/// The pointer stays valid until the next failing abgs call on this thread.
#[no_mangle]
pub extern "C" fn abgs_last_error_message() -> *const c_char {
    catch_unwind(|| LAST_ERROR.with(|e| e.borrow().as_ptr()))
        .unwrap_or(c"abgs: internal error".as_ptr())
}

/// Name of a status code, e.g. "ABGS_ERR_NULL" ("ABGS_UNKNOWN_STATUS" for others).
/// Static storage; never NULL.
#[no_mangle]
pub extern "C" fn abgs_status_name(status: c_int) -> *const c_char {
    let s: &'static CStr = match status {
        0 => c"ABGS_OK",
        1 => c"ABGS_ERR_NULL",
        2 => c"ABGS_ERR_INVALID_ARGUMENT",
        3 => c"ABGS_ERR_OUT_OF_RANGE",
        4 => c"ABGS_ERR_NON_FINITE",
        5 => c"ABGS_ERR_INVALID_SIZE",
        6 => c"ABGS_ERR_IO",
        7 => c"ABGS_ERR_PARSE",
        8 => c"ABGS_ERR_UNSUPPORTED_FORMAT",
        9 => c"ABGS_ERR_BUFFER_TOO_SMALL",
        10 => c"ABGS_ERR_EMPTY",
        11 => c"ABGS_ERR_NO_SIZES",
        12 => c"ABGS_ERR_BUSY",
        13 => c"ABGS_ERR_CANCELLED",
        14 => c"ABGS_ERR_NOT_AVAILABLE",
        99 => c"ABGS_ERR_INTERNAL",
        _ => c"ABGS_UNKNOWN_STATUS",
    };
    s.as_ptr()
}

/// The library version as "MAJOR.MINOR.PATCH" (static storage).
#[no_mangle]
pub extern "C" fn abgs_version() -> *const c_char {
    static V: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"unknown",
        };
    V.as_ptr()
}

/// The library version as `MAJOR * 10000 + MINOR * 100 + PATCH`; compare with
/// the header's `ABGS_VERSION_MAJOR` etc. to detect a header/library mismatch.
#[no_mangle]
pub extern "C" fn abgs_version_number() -> u32 {
    ABGS_VERSION_MAJOR * 10000 + ABGS_VERSION_MINOR * 100 + ABGS_VERSION_PATCH
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_constants_match_cargo() {
        let v = format!("{ABGS_VERSION_MAJOR}.{ABGS_VERSION_MINOR}.{ABGS_VERSION_PATCH}");
        assert_eq!(v, env!("CARGO_PKG_VERSION"));
        // SAFETY: abgs_version returns a static NUL-terminated string.
        let s = unsafe { CStr::from_ptr(abgs_version()) };
        assert_eq!(s.to_str().unwrap(), v);
    }

    #[test]
    fn panics_become_internal_errors() {
        let st = guard("t", || panic!("boom"));
        assert_eq!(st, abgs_status::ABGS_ERR_INTERNAL);
        // SAFETY: the message pointer is valid until the next failing call.
        let m = unsafe { CStr::from_ptr(abgs_last_error_message()) };
        assert!(m.to_str().unwrap().contains("boom"));
        for code in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 99] {
            // SAFETY: static strings.
            let n = unsafe { CStr::from_ptr(abgs_status_name(code)) };
            assert!(n.to_str().unwrap().starts_with("ABGS_"));
        }
    }
}
