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
    /// An argument is malformed (counts, lengths, options, struct_size).
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
    /// A call met a grid in use by another call (a mutation, or a free, against any use).
    ABGS_ERR_BUSY = 12,
    /// The caller's progress callback asked to stop.
    ABGS_ERR_CANCELLED = 13,
    /// The feature is not available in this build.
    ABGS_ERR_NOT_AVAILABLE = 14,
    /// A bug in abgs (a caught panic); the message says where.
    ABGS_ERR_INTERNAL = 99,
}

/// Names, descriptions and the list of every status, from one table: the
/// `match`es it makes are exhaustive, so a status added to the enum without a
/// row here does not compile, and `tests::header_status_docs_are_the_descriptions`
/// fails when a variant's doc comment (the header's text) differs from its row.
macro_rules! status_table {
    ($($v:ident => $msg:literal,)*) => {
        impl abgs_status {
            /// Every status, in declaration order.
            pub const ALL: &'static [abgs_status] = &[$(abgs_status::$v),*];

            /// The status's name as the header spells it, e.g. `ABGS_ERR_NULL`.
            pub const fn name(self) -> &'static CStr {
                match self {
                    $(abgs_status::$v => cstr(concat!(stringify!($v), "\0")),)*
                }
            }

            /// One line saying what the status means (the header's comment).
            pub const fn description(self) -> &'static CStr {
                match self {
                    $(abgs_status::$v => cstr(concat!($msg, "\0")),)*
                }
            }

            /// The status with number `n`, if there is one.
            pub fn from_int(n: c_int) -> Option<abgs_status> {
                Self::ALL.iter().copied().find(|s| *s as c_int == n)
            }
        }
    };
}

/// A `&CStr` from a literal with its NUL (evaluated at compile time).
const fn cstr(s: &'static str) -> &'static CStr {
    match CStr::from_bytes_with_nul(s.as_bytes()) {
        Ok(c) => c,
        Err(_) => panic!("status text with an inner NUL"),
    }
}

status_table! {
    ABGS_OK => "Success.",
    ABGS_ERR_NULL => "A required pointer is NULL.",
    ABGS_ERR_INVALID_ARGUMENT => "An argument is malformed (counts, lengths, options, struct_size).",
    ABGS_ERR_OUT_OF_RANGE => "An index is out of range (e.g. a triangle names a missing vertex).",
    ABGS_ERR_NON_FINITE => "A coordinate or parameter is NaN or infinite.",
    ABGS_ERR_INVALID_SIZE => "A size is not finite and > 0.",
    ABGS_ERR_IO => "A file could not be opened, read or written.",
    ABGS_ERR_PARSE => "A file's content is malformed.",
    ABGS_ERR_UNSUPPORTED_FORMAT => "The file extension names no supported format.",
    ABGS_ERR_BUFFER_TOO_SMALL => "A caller buffer is too small.",
    ABGS_ERR_EMPTY => "The grid would have no triangles.",
    ABGS_ERR_NO_SIZES => "The grid has no sizes yet.",
    ABGS_ERR_BUSY => "A call met a grid in use by another call (a mutation, or a free, against any use).",
    ABGS_ERR_CANCELLED => "The caller's progress callback asked to stop.",
    ABGS_ERR_NOT_AVAILABLE => "The feature is not available in this build.",
    ABGS_ERR_INTERNAL => "A bug in abgs (a caught panic); the message says where.",
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
            Error::Model(_) => abgs_status::ABGS_ERR_INVALID_ARGUMENT,
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

/// Checks that caller buffers a call reads and writes at once do not overlap
/// (two live `&mut`, or a `&` and a `&mut`, on the same bytes would be
/// undefined behaviour in Rust). Each part is (pointer, bytes, name); NULL or
/// empty parts are skipped.
pub(crate) fn disjoint(parts: &[(*const u8, usize, &str)]) -> FfiResult<()> {
    for (i, &(a, na, wa)) in parts.iter().enumerate() {
        for &(b, nb, wb) in &parts[i + 1..] {
            let (a0, b0) = (a as usize, b as usize);
            if a.is_null() || b.is_null() || na == 0 || nb == 0 {
                continue;
            }
            if a0 < b0.saturating_add(nb) && b0 < a0.saturating_add(na) {
                return err(
                    abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                    format!("{wa} and {wb} overlap"),
                );
            }
        }
    }
    Ok(())
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

/// Name of a status code, e.g. "ABGS_ERR_NULL" ("ABGS_UNKNOWN_STATUS" for a
/// number that is no status). Static storage; never NULL.
#[no_mangle]
pub extern "C" fn abgs_status_name(status: c_int) -> *const c_char {
    abgs_status::from_int(status)
        .map_or(c"ABGS_UNKNOWN_STATUS", abgs_status::name)
        .as_ptr()
}

/// One line saying what a status means (the header's comment on it), e.g.
/// "A required pointer is NULL."; "Unknown status." for a number that is no
/// status. Static storage; never NULL. The message of a particular failure
/// is `abgs_last_error_message`.
#[no_mangle]
pub extern "C" fn abgs_status_description(status: c_int) -> *const c_char {
    abgs_status::from_int(status)
        .map_or(c"Unknown status.", abgs_status::description)
        .as_ptr()
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
    }

    /// Every number from -1000 to 1000 either is a status, whose name,
    /// description and number round-trip, or is reported unknown.
    #[test]
    fn status_names_and_numbers_round_trip() {
        let mut seen = 0;
        for n in -1000..=1000 {
            // SAFETY: static strings.
            let name = unsafe { CStr::from_ptr(abgs_status_name(n)) }
                .to_str()
                .unwrap();
            // SAFETY: static strings.
            let desc = unsafe { CStr::from_ptr(abgs_status_description(n)) };
            match abgs_status::from_int(n) {
                Some(s) => {
                    seen += 1;
                    assert_eq!(s as c_int, n);
                    assert_eq!(name, format!("{s:?}"), "the name is the variant's");
                    assert!(desc.to_bytes().ends_with(b"."), "{desc:?}");
                }
                None => {
                    assert_eq!(name, "ABGS_UNKNOWN_STATUS");
                    assert_eq!(desc, c"Unknown status.");
                }
            }
        }
        assert_eq!(seen, abgs_status::ALL.len());
    }

    /// The header's enum (generated from the variants' doc comments) names
    /// every status with its number and the table's description.
    #[test]
    fn header_status_docs_are_the_descriptions() {
        let h = include_str!("../../include/abgs.h");
        let body = &h[h.find("typedef enum {").unwrap()..h.find("} abgs_status;").unwrap()];
        let lines: Vec<&str> = body.lines().map(str::trim).collect();
        let mut n = 0;
        for (i, l) in lines.iter().enumerate() {
            let Some((name, num)) = l.strip_suffix(',').and_then(|l| l.split_once(" = ")) else {
                continue;
            };
            let s = abgs_status::from_int(num.parse().unwrap()).unwrap();
            assert_eq!(s.name().to_str().unwrap(), name);
            let doc = lines[i - 1].trim_start_matches("// ");
            assert_eq!(s.description().to_str().unwrap(), doc, "{name}");
            n += 1;
        }
        assert_eq!(n, abgs_status::ALL.len());
    }
}
