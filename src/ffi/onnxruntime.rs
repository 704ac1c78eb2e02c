//! Loading ONNX Runtime's C API from its shared library (the `onnxruntime` feature),
//! for [`crate::gcn::runtime`]. It lives here because it is foreign code reached by
//! `dlopen`: this is the crate's only module with `unsafe`.
//!
//! `ort` is built with `alternative-backend` (the default build's tract backend needs
//! it, and Cargo features only add up), so `ort` never loads a library itself: the
//! table of C functions is read here and handed to `ort::set_api`.

use std::ffi::CStr;
use std::path::Path;
use std::sync::OnceLock;

/// The library stays loaded for the life of the process: `ort` keeps the function
/// pointers read from it.
static LIBRARY: OnceLock<libloading::Library> = OnceLock::new();

/// Opens the ONNX Runtime shared library at `path` (a bare file name is searched by the
/// system loader), checks that it offers at least the C API version `ort` was built for
/// ([`ort::sys::ORT_API_VERSION`]) and returns a copy of its function table with the
/// library's version string. Errors are messages for [`crate::Error::Model`].
///
/// Call once per process (the caller keeps the result in a `OnceLock`).
pub(crate) fn load_onnxruntime_api(path: &Path) -> Result<(ort::sys::OrtApi, String), String> {
    // SAFETY: loading runs the library's initialisers; libonnxruntime's are sound to run
    // once in any process (the wheel's Python module does the same).
    let lib = unsafe { libloading::Library::new(path) }
        .map_err(|e| format!("cannot load ONNX Runtime from '{}': {e}", path.display()))?;
    type GetApiBase = unsafe extern "system" fn() -> *const ort::sys::OrtApiBase;
    // SAFETY: `OrtGetApiBase` has this signature in every ONNX Runtime release (C API).
    let get_base = unsafe { lib.get::<GetApiBase>(b"OrtGetApiBase\0") }.map_err(|e| {
        format!(
            "'{}' is not ONNX Runtime (no OrtGetApiBase): {e}",
            path.display()
        )
    })?;
    // SAFETY: a plain C call without arguments; the result is checked for NULL.
    let base = unsafe { get_base() };
    if base.is_null() {
        return Err(format!("'{}': OrtGetApiBase returned NULL", path.display()));
    }
    // SAFETY: `base` is non-NULL and points to the library's static OrtApiBase; the
    // version string is a static NUL-terminated string owned by the library.
    let version = unsafe { CStr::from_ptr(((*base).GetVersionString)()) }
        .to_string_lossy()
        .into_owned();
    let minor = version
        .strip_prefix("1.")
        .and_then(|r| r.split('.').next())
        .and_then(|m| m.parse::<u32>().ok());
    if minor.is_none_or(|m| m < ort::sys::ORT_API_VERSION) {
        return Err(format!(
            "'{}' is ONNX Runtime {version}; 1.{} or newer is needed",
            path.display(),
            ort::sys::ORT_API_VERSION
        ));
    }
    // SAFETY: as above; GetApi returns NULL for an unsupported version (checked).
    let api = unsafe { ((*base).GetApi)(ort::sys::ORT_API_VERSION) };
    if api.is_null() {
        return Err(format!(
            "ONNX Runtime {version} does not offer C API version {}",
            ort::sys::ORT_API_VERSION
        ));
    }
    // SAFETY: `api` points to the library's static table for the requested version,
    // whose layout is `OrtApi` (the table of a newer library only appends to it); it
    // stays valid while the library is loaded, which is forever (LIBRARY).
    let table = unsafe { (*api).clone() };
    // A second successful load (not expected: the caller loads once) must not unload
    // its library either: its table may be in use.
    if let Err(lib) = LIBRARY.set(lib) {
        std::mem::forget(lib);
    }
    Ok((table, version))
}
