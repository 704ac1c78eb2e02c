//! The one rule by which a struct crossing the C ABI can grow without breaking
//! programs built against an older (or newer) header.
//!
//! # The rule
//! Every parameter, report, record and result struct begins with
//! `uint32_t struct_size`. The caller sets it to `sizeof` the struct *as its
//! header declares it* before handing the struct to the library, in or out:
//!
//! ```c
//! abgs_simplify_params sp = {.struct_size = sizeof sp};  /* rest zero   */
//! abgs_simplify_params_default(&sp);                      /* the defaults */
//! abgs_simplify_report rep = {.struct_size = sizeof rep};
//! abgs_simplify(grid, &sp, &out, &rep);
//! ```
//!
//! The library never reads or writes past `struct_size` bytes:
//! - **In** (parameters): the first `min(struct_size, own size)` bytes are
//!   taken; fields the caller's header does not have (an older header) keep
//!   the library's defaults. Bytes past the library's own size (a newer header
//!   on an older library) must be zero, i.e. the newer fields left at a value
//!   meaning "as before"; otherwise the call fails with
//!   `ABGS_ERR_INVALID_ARGUMENT` rather than ignore a setting.
//! - **Out** (reports, defaults): the library writes `min(struct_size, own
//!   size)` bytes and sets `struct_size` to that number, so a newer caller
//!   sees which fields an older library filled.
//! - A `struct_size` below the first released size of that struct, or above
//!   [`ABGS_MAX_STRUCT_SIZE`], is `ABGS_ERR_INVALID_ARGUMENT` (0 is the usual
//!   symptom of a forgotten initialisation).
//! - Structs the library hands to a callback (the iteration record) carry the
//!   library's own size: a caller reads a field only if it lies below
//!   `struct_size`.
//!
//! How the structs grow: fields are only appended, each new one at an offset at
//! or past the previous `sizeof` (never in what was trailing padding), and
//! `FIRST_SIZE` never changes. Every field is a type for which any bit pattern
//! is a valid Rust value (integers, floats, raw and optional function
//! pointers; enumerations cross as `uint32_t` with constants), so copying
//! caller bytes into a struct can never make an invalid Rust value.
//!
//! Cost: one bounded byte copy per struct and call.

use super::boundary::{abgs_status, err, FfiResult};
use std::mem::size_of;

/// Largest `struct_size` accepted: far above any struct of this library, low
/// enough that a garbage value is caught before it is used as a length.
pub const ABGS_MAX_STRUCT_SIZE: u32 = 65536;

/// A `#[repr(C)]` struct that follows the growth rule of this module.
///
/// # Safety
/// The type is `#[repr(C)]`, begins with a `u32` field `struct_size`, every
/// field accepts any bit pattern, and `FIRST_SIZE <= size_of::<Self>()` is a
/// field boundary of the layout.
pub(crate) unsafe trait Versioned: Copy {
    /// The struct's name in the header, for messages.
    const NAME: &'static str;
    /// `sizeof` of the struct in the first release that had it (frozen).
    const FIRST_SIZE: usize;
    /// The value the library starts from: defaults for parameters, zeros for
    /// reports; its `struct_size` is the library's own size.
    fn initial() -> Self;
}

/// `size_of::<T>()` as the `u32` stamped into `struct_size`.
pub(crate) fn own_size<T: Versioned>() -> u32 {
    // All structs are far below ABGS_MAX_STRUCT_SIZE (a unit test checks each).
    size_of::<T>() as u32
}

/// Reads and checks the caller's `struct_size` at `p` (non-NULL, aligned).
///
/// # Safety
/// `p` points to at least four readable bytes.
unsafe fn caller_size<T: Versioned>(p: *const T, what: &str) -> FfiResult<usize> {
    // SAFETY: the caller guarantees four readable bytes; `struct_size` is the
    // first field, so it lies at offset 0 with u32 alignment (T's is larger).
    let n = unsafe { std::ptr::read(p as *const u32) };
    if (n as usize) < T::FIRST_SIZE || n > ABGS_MAX_STRUCT_SIZE {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!(
                "{what}->struct_size = {n}: set it to sizeof({}) ({} in this library's header) \
                 before the call",
                T::NAME,
                size_of::<T>()
            ),
        );
    }
    Ok(n as usize)
}

fn check_aligned<T>(p: *const T, what: &str) -> FfiResult<()> {
    if (p as usize).is_multiple_of(std::mem::align_of::<T>()) {
        Ok(())
    } else {
        err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what} is misaligned"),
        )
    }
}

/// Reads a caller struct by the growth rule: `None` for NULL, else the
/// library's initial value overlaid with the caller's first
/// `min(struct_size, own size)` bytes.
///
/// # Safety
/// A non-NULL `p` points to `struct_size` readable bytes.
pub(crate) unsafe fn read_in<T: Versioned>(p: *const T, what: &str) -> FfiResult<Option<T>> {
    if p.is_null() {
        return Ok(None);
    }
    check_aligned(p, what)?;
    // SAFETY: non-NULL and aligned; at least FIRST_SIZE >= 4 readable bytes by contract.
    let n = unsafe { caller_size(p, what)? };
    let own = size_of::<T>();
    if n > own {
        // SAFETY: the caller declared n readable bytes.
        let tail = unsafe { std::slice::from_raw_parts((p as *const u8).add(own), n - own) };
        if tail.iter().any(|&b| b != 0) {
            return err(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                format!(
                    "{what} sets fields this library version ({}) does not know \
                     (struct_size {n} > {own}): link against a newer abgs",
                    crate::VERSION
                ),
            );
        }
    }
    let mut v = T::initial();
    // SAFETY: min(n, own) bytes are readable at p and writable in v; every bit
    // pattern is a valid T (the Versioned contract), so overlaying is sound.
    unsafe {
        std::ptr::copy_nonoverlapping(p as *const u8, &mut v as *mut T as *mut u8, n.min(own))
    };
    // SAFETY: struct_size is the first field (the Versioned contract).
    unsafe { std::ptr::write(&mut v as *mut T as *mut u32, own_size::<T>()) };
    Ok(Some(v))
}

/// As [`read_in`], NULL being an error.
///
/// # Safety
/// As [`read_in`].
pub(crate) unsafe fn read_required<T: Versioned>(p: *const T, what: &str) -> FfiResult<T> {
    // SAFETY: forwarded contract.
    match unsafe { read_in(p, what)? } {
        Some(v) => Ok(v),
        None => err(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL")),
    }
}

/// Checks an out-struct before any work is done (so that a bad `struct_size`
/// fails fast, not after a long computation). NULL passes when `optional`.
///
/// # Safety
/// A non-NULL `p` points to at least four readable bytes.
pub(crate) unsafe fn check_out<T: Versioned>(
    p: *mut T,
    what: &str,
    optional: bool,
) -> FfiResult<()> {
    if p.is_null() {
        return if optional {
            Ok(())
        } else {
            err(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL"))
        };
    }
    check_aligned(p as *const T, what)?;
    // SAFETY: forwarded contract.
    unsafe { caller_size(p as *const T, what) }.map(|_| ())
}

/// Writes `v` into the caller's struct by the growth rule (NULL is skipped):
/// `min(struct_size, own size)` bytes, then `struct_size` = that number.
///
/// # Safety
/// A non-NULL `p` points to `struct_size` writable bytes.
pub(crate) unsafe fn write_out<T: Versioned>(p: *mut T, v: &T, what: &str) -> FfiResult<()> {
    if p.is_null() {
        return Ok(());
    }
    check_aligned(p as *const T, what)?;
    // SAFETY: forwarded contract.
    let n = unsafe { caller_size(p as *const T, what)? }.min(size_of::<T>());
    // SAFETY: n bytes are writable at p (n <= struct_size) and readable in v;
    // raw bytes are copied, no reference to the caller's memory is made.
    unsafe {
        std::ptr::copy_nonoverlapping(v as *const T as *const u8, p as *mut u8, n);
        std::ptr::write(p as *mut u32, n as u32);
    }
    Ok(())
}

/// Reads `n` caller structs laid out `struct_size` bytes apart, where every
/// element states the same `struct_size` (the caller's `sizeof`).
///
/// # Safety
/// A non-NULL `p` points to `n` elements of the stated size.
pub(crate) unsafe fn read_array<T: Versioned>(
    p: *const T,
    n: usize,
    what: &str,
) -> FfiResult<Vec<T>> {
    if n == 0 {
        return Ok(Vec::new());
    }
    if p.is_null() {
        return err(abgs_status::ABGS_ERR_NULL, format!("{what} is NULL"));
    }
    check_aligned(p, what)?;
    // SAFETY: the first element is readable by contract.
    let stride = unsafe { caller_size(p, &format!("{what}[0]"))? };
    if !stride.is_multiple_of(std::mem::align_of::<T>()) {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what}: struct_size {stride} is not a multiple of the alignment"),
        );
    }
    if n.checked_mul(stride)
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return err(
            abgs_status::ABGS_ERR_INVALID_ARGUMENT,
            format!("{what}: {n} elements too many"),
        );
    }
    let mut v = Vec::with_capacity(n.min(1 << 16));
    for i in 0..n {
        // SAFETY: element i starts i * stride bytes in, within the caller's array.
        let e = unsafe { (p as *const u8).add(i * stride) } as *const T;
        let name = format!("{what}[{i}]");
        // SAFETY: n elements of `stride` bytes by contract.
        if unsafe { caller_size(e, &name)? } != stride {
            return err(
                abgs_status::ABGS_ERR_INVALID_ARGUMENT,
                format!("{name}->struct_size differs from {what}[0]'s ({stride})"),
            );
        }
        // SAFETY: as above, aligned (stride is a multiple of the alignment).
        v.extend(unsafe { read_in(e, &name)? });
    }
    Ok(v)
}

/// Implements [`Versioned`] for a C struct:
/// `versioned!(type, FIRST_SIZE, initial-expression)`, or
/// `versioned!(type, FIRST_SIZE)` for a report whose initial value is all
/// zeros (`Default`) with its `struct_size`.
macro_rules! versioned {
    ($t:ident, $first:expr) => {
        $crate::ffi::versioned::versioned!(
            $t,
            $first,
            $t {
                struct_size: $crate::ffi::versioned::own_size::<$t>(),
                ..Default::default()
            }
        );
    };
    ($t:ty, $first:expr, $init:expr) => {
        // SAFETY: the type is #[repr(C)], starts with `struct_size: u32`, has
        // only integer / float / pointer fields, and the unit test
        // `every_struct_follows_the_rule` checks FIRST_SIZE against its layout.
        unsafe impl $crate::ffi::versioned::Versioned for $t {
            const NAME: &'static str = stringify!($t);
            const FIRST_SIZE: usize = $first;
            fn initial() -> Self {
                $init
            }
        }
    };
}
pub(crate) use versioned;

#[cfg(test)]
mod tests {
    use super::*;

    /// A struct that grew: version 1 ended before `b`.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Grown {
        struct_size: u32,
        a: f64,
        b: f64,
    }
    versioned!(
        Grown,
        16,
        Grown {
            struct_size: 24,
            a: 1.0,
            b: 2.0
        }
    );

    /// A caller buffer: the struct followed by canary bytes.
    #[repr(C, align(8))]
    struct Buf([u8; 64]);

    #[test]
    fn an_older_caller_gets_defaults_for_fields_it_lacks() {
        let mut buf = Buf([0xAB; 64]);
        buf.0[..4].copy_from_slice(&16u32.to_ne_bytes());
        buf.0[8..16].copy_from_slice(&5.0f64.to_ne_bytes());
        // SAFETY: 64 readable bytes, aligned.
        let v = unsafe { read_in(buf.0.as_ptr() as *const Grown, "p") }
            .ok()
            .flatten()
            .unwrap();
        assert_eq!((v.struct_size, v.a, v.b), (24, 5.0, 2.0));
    }

    #[test]
    fn an_older_caller_gets_only_its_bytes_written() {
        let mut buf = Buf([0xAB; 64]);
        buf.0[..4].copy_from_slice(&16u32.to_ne_bytes());
        let v = Grown {
            struct_size: 24,
            a: 7.0,
            b: 8.0,
        };
        // SAFETY: 64 writable bytes, aligned.
        assert!(unsafe { write_out(buf.0.as_mut_ptr() as *mut Grown, &v, "p") }.is_ok());
        assert_eq!(&buf.0[..4], &16u32.to_ne_bytes());
        assert_eq!(&buf.0[8..16], &7.0f64.to_ne_bytes());
        assert!(
            buf.0[16..].iter().all(|&b| b == 0xAB),
            "wrote past struct_size"
        );
    }

    #[test]
    fn a_newer_caller_is_accepted_only_with_a_zero_tail() {
        let mut buf = Buf([0; 64]);
        buf.0[..4].copy_from_slice(&40u32.to_ne_bytes());
        // SAFETY: 64 readable bytes, aligned.
        let ok = unsafe { read_in(buf.0.as_ptr() as *const Grown, "p") };
        assert_eq!(ok.ok().flatten().map(|v| v.struct_size), Some(24));
        buf.0[30] = 1;
        // SAFETY: as above.
        let bad = unsafe { read_in(buf.0.as_ptr() as *const Grown, "p") };
        let e = bad.err().unwrap();
        assert_eq!(e.0, abgs_status::ABGS_ERR_INVALID_ARGUMENT);
        assert!(e.1.contains("does not know"), "{}", e.1);
        // A newer caller's report: the library writes its 24 bytes, says so,
        // and leaves the caller's newer fields alone.
        let mut out = Buf([0xCD; 64]);
        out.0[..4].copy_from_slice(&40u32.to_ne_bytes());
        let v = Grown::initial();
        // SAFETY: 64 writable bytes, aligned.
        assert!(unsafe { write_out(out.0.as_mut_ptr() as *mut Grown, &v, "p") }.is_ok());
        assert_eq!(&out.0[..4], &24u32.to_ne_bytes());
        assert!(out.0[24..].iter().all(|&b| b == 0xCD));
    }

    #[test]
    fn a_forgotten_or_garbage_size_is_refused() {
        for n in [0u32, 4, 15, ABGS_MAX_STRUCT_SIZE + 1, u32::MAX] {
            let mut buf = Buf([0; 64]);
            buf.0[..4].copy_from_slice(&n.to_ne_bytes());
            // SAFETY: the size is refused before more than 4 bytes are read.
            let r = unsafe { read_in(buf.0.as_ptr() as *const Grown, "params") };
            let e = r.err().unwrap();
            assert_eq!(e.0, abgs_status::ABGS_ERR_INVALID_ARGUMENT);
            assert!(e.1.contains("params->struct_size"), "{}", e.1);
            // SAFETY: as above; nothing is written.
            let w = unsafe { write_out(buf.0.as_mut_ptr() as *mut Grown, &Grown::initial(), "r") };
            assert!(w.is_err());
            assert_eq!(
                &buf.0[..4],
                &n.to_ne_bytes(),
                "a refused struct is not touched"
            );
        }
    }

    #[test]
    fn arrays_use_the_callers_stride_and_agree_on_it() {
        #[repr(C, align(8))]
        struct Arr([u8; 96]);
        let mut a = Arr([0; 96]);
        for (i, off) in [0usize, 32, 64].into_iter().enumerate() {
            a.0[off..off + 4].copy_from_slice(&32u32.to_ne_bytes());
            a.0[off + 8..off + 16].copy_from_slice(&(i as f64).to_ne_bytes());
        }
        // SAFETY: three elements of 32 bytes.
        let v = unsafe { read_array(a.0.as_ptr() as *const Grown, 3, "s") }
            .ok()
            .unwrap();
        assert_eq!(v.iter().map(|g| g.a).collect::<Vec<_>>(), [0.0, 1.0, 2.0]);
        a.0[64..68].copy_from_slice(&24u32.to_ne_bytes());
        // SAFETY: as above.
        let e = unsafe { read_array(a.0.as_ptr() as *const Grown, 3, "s") }
            .err()
            .unwrap();
        assert!(e.1.contains("s[2]->struct_size differs"), "{}", e.1);
    }
}
