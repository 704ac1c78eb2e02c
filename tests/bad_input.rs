//! The bad-input matrix: one table of hostile or broken inputs — files, C
//! arguments and parameters — each with the exact status it must give, a
//! word the message must contain (so that it names the problem), and the
//! check that nothing the caller gave was modified (input buffers, files and
//! parameter structs are compared byte for byte after the call; on failure a
//! grid out-pointer is NULL). Everything goes through the C ABI, as a C
//! caller would use it.
#![allow(clippy::type_complexity)]

use abgs::ffi::*;
use std::ffi::{c_void, CStr, CString};
use std::path::PathBuf;
use std::ptr::{null, null_mut};

/// What a case's call gave back.
struct Outcome {
    status: abgs_status,
    message: String,
}

fn last_message() -> String {
    // SAFETY: the library returns a valid NUL-terminated thread-local string.
    unsafe { CStr::from_ptr(abgs_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn outcome(status: abgs_status) -> Outcome {
    let message = if status == abgs_status::ABGS_OK {
        String::new()
    } else {
        last_message()
    };
    Outcome { status, message }
}

/// A unit cube (8 vertices, 12 triangles, outward) as C arrays.
fn cube() -> (Vec<f64>, Vec<u32>) {
    let v = [
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let t: [[u32; 3]; 12] = [
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    (v.concat(), t.concat())
}

/// Builds a grid from arrays through the ABI, checking that the arrays are
/// unchanged and that a failure leaves `*out` NULL.
fn from_arrays(
    xyz: &[f64],
    n_v: usize,
    tris: &[u32],
    n_t: usize,
    sizes: Option<&[f64]>,
) -> (Outcome, *mut abgs_grid) {
    let (x0, t0, s0) = (bits(xyz), tris.to_vec(), sizes.map(bits));
    let mut g = std::ptr::dangling_mut::<abgs_grid>(); // garbage the call must overwrite
                                                       // SAFETY: the slices hold at least what the counts say (cases lie only
                                                       // through the counts that the library must check before reading).
    let st = unsafe {
        abgs_grid_from_arrays(
            if xyz.is_empty() { null() } else { xyz.as_ptr() },
            n_v,
            if tris.is_empty() {
                null()
            } else {
                tris.as_ptr()
            },
            n_t,
            sizes.map_or(null(), |s| s.as_ptr()),
            &mut g,
        )
    };
    let o = outcome(st);
    assert_eq!(bits(xyz), x0, "xyz modified");
    assert_eq!(tris, &t0[..], "triangles modified");
    assert_eq!(sizes.map(bits), s0, "sizes modified");
    if st != abgs_status::ABGS_OK {
        assert!(g.is_null(), "out_grid not NULL after a failure");
    }
    (o, g)
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

fn free(g: *mut abgs_grid) {
    // SAFETY: a grid from this library, freed once.
    assert_eq!(unsafe { abgs_grid_free(g) }, abgs_status::ABGS_OK);
}

/// Runs `f` on the cube grid (with sizes when `sized`), then frees it.
fn with_cube(sized: bool, f: impl FnOnce(*mut abgs_grid) -> Outcome) -> Outcome {
    let (v, t) = cube();
    let s = [0.3; 8];
    let (o, g) = from_arrays(&v, 8, &t, 12, sized.then_some(&s[..]));
    assert_eq!(o.status, abgs_status::ABGS_OK, "{}", o.message);
    let r = f(g);
    free(g);
    r
}

/// Writes `bytes` to a fresh file with extension `ext`, loads it through the
/// ABI, and checks the file is unchanged and a failure leaves `*out` NULL.
fn load_bytes(ext: &str, bytes: &[u8]) -> Outcome {
    let dir = tmp_dir();
    let path = dir.path().join(format!("case.{ext}"));
    std::fs::write(&path, bytes).unwrap();
    let o = load_path(&path);
    assert_eq!(
        std::fs::read(&path).unwrap(),
        bytes,
        "the file was modified"
    );
    o
}

fn load_path(path: &std::path::Path) -> Outcome {
    let c = CString::new(path.to_str().unwrap()).unwrap();
    let mut g = std::ptr::dangling_mut::<abgs_grid>();
    // SAFETY: a NUL-terminated path and a writable out-pointer.
    let st = unsafe { abgs_grid_load(c.as_ptr(), &mut g) };
    let o = outcome(st);
    if st == abgs_status::ABGS_OK {
        free(g);
    } else {
        assert!(g.is_null(), "out_grid not NULL after a failure");
    }
    o
}

/// A fresh directory, removed with everything in it when dropped.
fn tmp_dir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("abgs-bad-input-")
        .tempdir()
        .unwrap()
}

/// A binary STL: 80-byte header, the stated count, then `actual` triangles.
fn binary_stl(stated: u32, actual: usize) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&stated.to_le_bytes());
    for i in 0..actual {
        let z = i as f32;
        for f in [0.0f32, 0.0, 1.0, 0.0, 0.0, z, 1.0, 0.0, z, 0.0, 1.0, z] {
            b.extend_from_slice(&f.to_le_bytes());
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// The cube as OBJ text with the given per-line edits.
fn obj(vertex0: &str, extra_face: &str) -> Vec<u8> {
    let (v, t) = cube();
    let mut s = String::new();
    for (i, p) in v.chunks(3).enumerate() {
        if i == 0 && !vertex0.is_empty() {
            s += &format!("v {vertex0}\n");
        } else {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
    }
    for f in t.chunks(3) {
        s += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    s += extra_face;
    s.into_bytes()
}

/// The sized cube serialised through the ABI (`.abgs` bytes).
fn cube_abgs() -> Vec<u8> {
    let mut b = Vec::new();
    with_cube(true, |g| {
        let mut n = 0usize;
        // SAFETY: a valid grid; size query (NULL, 0), then a buffer of n bytes.
        unsafe {
            assert_eq!(abgs_grid_serialize(g, null_mut(), 0, &mut n), ABGS_OK);
            b = vec![0u8; n];
            assert_eq!(
                abgs_grid_serialize(g, b.as_mut_ptr().cast(), n, &mut n),
                ABGS_OK
            );
        }
        outcome(ABGS_OK)
    });
    b
}

/// `cube_abgs()` edited by `f`, its checksum made right again when `reseal`.
fn cube_abgs_with(f: impl FnOnce(&mut Vec<u8>), reseal: bool) -> Vec<u8> {
    let mut b = cube_abgs();
    f(&mut b);
    if reseal {
        let n = b.len() - 4;
        let crc = crc32fast::hash(&b[..n]);
        b[n..].copy_from_slice(&crc.to_le_bytes());
    }
    b
}

/// Deserialises `bytes` through the ABI, checking that they are unchanged
/// and that a failure leaves `*out` NULL.
fn deserialize(bytes: &[u8]) -> Outcome {
    let copy = bytes.to_vec();
    let mut g = std::ptr::dangling_mut::<abgs_grid>();
    // SAFETY: `bytes` is readable for its length; `g` is writable.
    let st = unsafe { abgs_grid_deserialize(bytes.as_ptr().cast(), bytes.len(), &mut g) };
    let o = outcome(st);
    assert_eq!(bytes, copy, "the buffer was modified");
    if st == ABGS_OK {
        free(g);
    } else {
        assert!(g.is_null(), "out_grid not NULL after a failure");
    }
    o
}

/// Simplify parameters from the defaults, edited by `f`, run on a sized cube;
/// the parameter struct must come back unchanged.
/// A parameter struct of type `T` from the library's defaults
/// (`default_fn`), with `struct_size` set first as the ABI asks.
fn defaults<T: Copy>(default_fn: unsafe extern "C" fn(*mut T) -> abgs_status) -> T {
    // SAFETY: all-zero bytes are a valid value of these plain C structs.
    let mut p: T = unsafe { std::mem::zeroed() };
    // SAFETY: every ABI struct begins with `uint32_t struct_size`.
    unsafe {
        std::ptr::write(
            &mut p as *mut T as *mut u32,
            std::mem::size_of::<T>() as u32,
        )
    };
    // SAFETY: a writable struct with struct_size set.
    assert_eq!(unsafe { default_fn(&mut p) }, abgs_status::ABGS_OK);
    p
}

/// Runs a call that makes a grid from `params` (edited from the defaults by
/// `edit`) on the cube; checks that `params` came back unchanged and that a
/// failure leaves the out-grid NULL.
fn make_with<T: Copy + std::fmt::Debug>(
    sized: bool,
    default_fn: unsafe extern "C" fn(*mut T) -> abgs_status,
    edit: impl FnOnce(&mut T),
    call: impl FnOnce(*mut abgs_grid, &T, &mut *mut abgs_grid) -> abgs_status,
) -> Outcome {
    with_cube(sized, |g| {
        let mut p = defaults(default_fn);
        edit(&mut p);
        let before = format!("{p:?}");
        let mut out = std::ptr::dangling_mut::<abgs_grid>();
        let st = call(g, &p, &mut out);
        assert_eq!(format!("{p:?}"), before, "params modified");
        let o = outcome(st);
        if st == abgs_status::ABGS_OK {
            free(out);
        } else {
            assert!(out.is_null());
        }
        o
    })
}

fn simplify_with(f: impl FnOnce(&mut abgs_simplify_params)) -> Outcome {
    make_with(true, abgs_simplify_params_default, f, |g, p, out| {
        // SAFETY: valid grid, params and out-pointer.
        unsafe { abgs_simplify(g, p, out, null_mut()) }
    })
}

fn remesh_with(f: impl FnOnce(&mut abgs_remesh_params)) -> Outcome {
    make_with(false, abgs_remesh_params_default, f, |g, p, out| {
        // SAFETY: valid grid, params and out-pointer.
        unsafe { abgs_grid_remesh(g, null(), p, out, null_mut()) }
    })
}

fn size_with(f: impl FnOnce(&mut abgs_size_params, &mut abgs_size_source)) -> Outcome {
    with_cube(false, |g| {
        let mut p = defaults(abgs_size_params_default);
        // SAFETY: zeroed is a valid value of this plain C struct.
        let mut src: abgs_size_source = unsafe { std::mem::zeroed() };
        src.struct_size = std::mem::size_of::<abgs_size_source>() as u32;
        src.size = 0.1;
        src.radius = 0.2;
        f(&mut p, &mut src);
        if p.n_sources == 1 {
            p.sources = &src;
        }
        let (before, sbefore) = (format!("{p:?}"), format!("{src:?}"));
        // SAFETY: valid grid and params; sources points to `src`.
        let st = unsafe { abgs_compute_size(g, &p, null_mut()) };
        let o = outcome(st);
        assert_eq!((format!("{p:?}"), format!("{src:?}")), (before, sbefore));
        // A failed compute leaves the grid without sizes.
        if st != abgs_status::ABGS_OK {
            let mut h = 0.0;
            // SAFETY: valid grid, point and out-pointer.
            let q = unsafe { abgs_query_size(g, [0.5, 0.5, 0.5].as_ptr(), &mut h) };
            assert_eq!(q, abgs_status::ABGS_ERR_NO_SIZES);
        }
        o
    })
}

/// A progress callback that stops at once.
unsafe extern "C" fn cancel_at_once(_: *const abgs_iteration_record, _: *mut c_void) -> i32 {
    1
}

use abgs_status::*;

/// (name, expected status, a word the message must contain, the call).
fn cases() -> Vec<(
    &'static str,
    abgs_status,
    &'static str,
    Box<dyn Fn() -> Outcome>,
)> {
    let (v, t) = cube();
    let (v2, t2) = (v.clone(), t.clone());
    let c = |f: Box<dyn Fn() -> Outcome>| f;
    vec![
        // ---- files ----
        (
            "empty STL",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| load_bytes("stl", b""))),
        ),
        (
            "empty OBJ",
            ABGS_ERR_EMPTY,
            "",
            c(Box::new(|| load_bytes("obj", b""))),
        ),
        (
            "STL truncated in a triangle",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                let mut b = binary_stl(2, 2);
                b.truncate(b.len() - 20);
                load_bytes("stl", &b)
            })),
        ),
        (
            "STL count says 1000, file has 2",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| load_bytes("stl", &binary_stl(1000, 2)))),
        ),
        (
            "STL count 2^32-1 (memory bomb)",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| load_bytes("stl", &binary_stl(u32::MAX, 1)))),
        ),
        (
            "ASCII STL with NaN",
            ABGS_ERR_PARSE,
            "NaN",
            c(Box::new(|| {
                load_bytes("stl",
            b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n")
            })),
        ),
        (
            "OBJ with inf",
            ABGS_ERR_NON_FINITE,
            "",
            c(Box::new(|| load_bytes("obj", &obj("inf 0 0", "")))),
        ),
        (
            "OBJ at 1e308 (finite, beyond ±1e150)",
            ABGS_ERR_NON_FINITE,
            "1e150",
            c(Box::new(|| {
                load_bytes(
                    "obj",
                    &obj("-1e308 -1e308 -1e308", "v 1e308 1e308 1e308\nf 1 9 2\n"),
                )
            })),
        ),
        (
            "OBJ face names vertex 99",
            ABGS_ERR_PARSE,
            "99",
            c(Box::new(|| load_bytes("obj", &obj("", "f 1 2 99\n")))),
        ),
        (
            "OBJ with only degenerate triangles",
            ABGS_ERR_EMPTY,
            "",
            c(Box::new(|| {
                load_bytes("obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n")
            })),
        ),
        (
            "OFF counts 10^12 vertices (memory bomb)",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                load_bytes("off", b"OFF\n1000000000000 1 0\n0 0 0\n")
            })),
        ),
        (
            "OFF truncated",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                load_bytes("off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n")
            })),
        ),
        (
            "PLY with 2^32-1 vertices (memory bomb)",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                load_bytes("ply",
            b"ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
            })),
        ),
        (
            "MSH 4.1 truncated",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                load_bytes(
                    "msh",
                    b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n",
                )
            })),
        ),
        (
            "VTK with 10^12 points (memory bomb)",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| {
                load_bytes("vtk",
            b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 1000000000000 double\n0 0 0\n")
            })),
        ),
        (
            "VTU that is not XML",
            ABGS_ERR_PARSE,
            "",
            c(Box::new(|| load_bytes("vtu", b"\x00\xff garbage <<<"))),
        ),
        (
            "Medit without triangles",
            ABGS_ERR_EMPTY,
            "",
            c(Box::new(|| {
                load_bytes(
                    "mesh",
                    b"MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nEnd\n",
                )
            })),
        ),
        (
            "unknown extension",
            ABGS_ERR_UNSUPPORTED_FORMAT,
            "xyz",
            c(Box::new(|| load_bytes("xyz", b"1 2 3\n"))),
        ),
        (
            "missing file",
            ABGS_ERR_IO,
            "no-such-file",
            c(Box::new(|| {
                load_path(&tmp_dir().path().join("no-such-file.stl"))
            })),
        ),
        (
            "a directory",
            ABGS_ERR_IO,
            "",
            c(Box::new(|| {
                load_path(&tmp_dir().path().join("d.stl").tap_mkdir())
            })),
        ),
        (
            "non-manifold fan (3 triangles on an edge) loads",
            ABGS_OK,
            "",
            c(Box::new(|| {
                load_bytes(
                    "obj",
                    b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
                )
            })),
        ),
        (
            "inconsistent winding loads",
            ABGS_OK,
            "",
            c(Box::new(|| {
                load_bytes("obj", &{
                    let mut b = obj("", "");
                    let s = String::from_utf8(b.clone())
                        .unwrap()
                        .replacen("f 1 3 2", "f 1 2 3", 1);
                    b = s.into_bytes();
                    b
                })
            })),
        ),
        (
            "duplicate triangles load",
            ABGS_OK,
            "",
            c(Box::new(|| load_bytes("obj", &obj("", "f 1 3 2\n")))),
        ),
        (
            "open sheet loads",
            ABGS_OK,
            "",
            c(Box::new(|| {
                load_bytes("obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
            })),
        ),
        // ---- C arguments ----
        (
            "xyz NULL",
            ABGS_ERR_NULL,
            "xyz",
            c(Box::new({
                let t = t.clone();
                move || from_arrays(&[], 8, &t, 12, None).0
            })),
        ),
        (
            "triangles NULL",
            ABGS_ERR_NULL,
            "triangles",
            c(Box::new({
                let v = v.clone();
                move || from_arrays(&v, 8, &[], 12, None).0
            })),
        ),
        (
            "out_grid NULL",
            ABGS_ERR_NULL,
            "out_grid",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    // SAFETY: valid arrays, NULL out-pointer (reported).
                    outcome(unsafe {
                        abgs_grid_from_arrays(v.as_ptr(), 8, t.as_ptr(), 12, null(), null_mut())
                    })
                }
            })),
        ),
        (
            "no vertices",
            ABGS_ERR_EMPTY,
            "0 vertices",
            c(Box::new({
                let t = t.clone();
                move || from_arrays(&[], 0, &t, 12, None).0
            })),
        ),
        (
            "NaN coordinate",
            ABGS_ERR_NON_FINITE,
            "",
            c(Box::new({
                let (mut v, t) = (v.clone(), t.clone());
                v[4] = f64::NAN;
                move || from_arrays(&v, 8, &t, 12, None).0
            })),
        ),
        (
            "-inf coordinate",
            ABGS_ERR_NON_FINITE,
            "",
            c(Box::new({
                let (mut v, t) = (v.clone(), t.clone());
                v[0] = f64::NEG_INFINITY;
                move || from_arrays(&v, 8, &t, 12, None).0
            })),
        ),
        (
            "coordinates at 1e308 (beyond ±1e150)",
            ABGS_ERR_NON_FINITE,
            "1e150",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    let v: Vec<f64> = v.iter().map(|x| (x - 0.5) * 1.6e308).collect();
                    from_arrays(&v, 8, &t, 12, None).0
                }
            })),
        ),
        (
            "a cube at 1e100 (above the extent range)",
            ABGS_ERR_INVALID_ARGUMENT,
            "rescale",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    let v: Vec<f64> = v.iter().map(|x| x * 1e100).collect();
                    from_arrays(&v, 8, &t, 12, None).0
                }
            })),
        ),
        (
            "a cube at 1e-300 (below the extent range)",
            ABGS_ERR_INVALID_ARGUMENT,
            "rescale",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    let v: Vec<f64> = v.iter().map(|x| x * 1e-300).collect();
                    from_arrays(&v, 8, &t, 12, None).0
                }
            })),
        ),
        (
            "index out of range",
            ABGS_ERR_OUT_OF_RANGE,
            "8",
            c(Box::new({
                let (v, mut t) = (v.clone(), t.clone());
                t[5] = 8;
                move || from_arrays(&v, 8, &t, 12, None).0
            })),
        ),
        (
            "size 0",
            ABGS_ERR_INVALID_SIZE,
            "",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    let mut s = vec![0.3; 8];
                    s[3] = 0.0;
                    from_arrays(&v, 8, &t, 12, Some(&s)).0
                }
            })),
        ),
        (
            "size NaN",
            ABGS_ERR_INVALID_SIZE,
            "",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || {
                    let mut s = vec![0.3; 8];
                    s[0] = f64::NAN;
                    from_arrays(&v, 8, &t, 12, Some(&s)).0
                }
            })),
        ),
        (
            "n_vertices over 2^32-1",
            ABGS_ERR_INVALID_ARGUMENT,
            "2^32",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || from_arrays(&v, 1 << 33, &t, 12, None).0
            })),
        ),
        (
            "n_triangles * 3 overflows",
            ABGS_ERR_INVALID_ARGUMENT,
            "n_triangles",
            c(Box::new({
                let (v, t) = (v.clone(), t.clone());
                move || from_arrays(&v, 8, &t, usize::MAX / 2, None).0
            })),
        ),
        (
            "query point NULL",
            ABGS_ERR_NULL,
            "point",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let mut h = 0.0;
                    // SAFETY: valid grid; NULL point (reported).
                    outcome(unsafe { abgs_query_size(g, null(), &mut h) })
                })
            })),
        ),
        (
            "query at NaN",
            ABGS_ERR_NON_FINITE,
            "",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let mut h = 0.0;
                    // SAFETY: valid grid, point and out-pointer.
                    outcome(unsafe { abgs_query_size(g, [f64::NAN, 0.0, 0.0].as_ptr(), &mut h) })
                })
            })),
        ),
        (
            "query without sizes",
            ABGS_ERR_NO_SIZES,
            "sizes",
            c(Box::new(|| {
                with_cube(false, |g| {
                    let mut h = 0.0;
                    // SAFETY: valid grid, point and out-pointer.
                    outcome(unsafe { abgs_query_size(g, [0.0; 3].as_ptr(), &mut h) })
                })
            })),
        ),
        (
            "volume query with beta NaN",
            ABGS_ERR_NON_FINITE,
            "beta",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let mut h = 0.0;
                    // SAFETY: valid grid, point and out-pointer.
                    outcome(unsafe {
                        abgs_query_size_volume(g, [0.0; 3].as_ptr(), f64::NAN, &mut h)
                    })
                })
            })),
        ),
        (
            "batch output overlaps the points",
            ABGS_ERR_INVALID_ARGUMENT,
            "overlap",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let mut buf = vec![0.25f64; 12];
                    let before = bits(&buf);
                    // SAFETY: 4 points in 12 doubles, output aliasing them (reported).
                    let st =
                        unsafe { abgs_query_sizes(g, buf.as_ptr(), 4, buf.as_mut_ptr().add(3)) };
                    assert_eq!(bits(&buf), before);
                    outcome(st)
                })
            })),
        ),
        (
            "hint with a garbage value is safe",
            ABGS_OK,
            "",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let (mut h, mut hint) = (0.0, 0xDEAD_BEEF_u32);
                    // SAFETY: valid grid, point, hint and out-pointer.
                    outcome(unsafe {
                        abgs_query_size_hinted(g, [0.5, 0.5, 2.0].as_ptr(), &mut hint, &mut h)
                    })
                })
            })),
        ),
        (
            "copy buffer too small",
            ABGS_ERR_BUFFER_TOO_SMALL,
            "24 needed",
            c(Box::new(|| {
                with_cube(false, |g| {
                    let mut buf = vec![7.0; 23];
                    // SAFETY: a buffer of 23 doubles, capacity 23.
                    let st = unsafe { abgs_grid_copy_vertices(g, buf.as_mut_ptr(), 23) };
                    assert!(buf.iter().all(|&x| x == 7.0), "written despite the error");
                    outcome(st)
                })
            })),
        ),
        (
            "set_sizes with the wrong count",
            ABGS_ERR_INVALID_ARGUMENT,
            "",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let s = [0.5; 7];
                    // SAFETY: 7 doubles.
                    outcome(unsafe { abgs_grid_set_sizes(g, s.as_ptr(), 7) })
                })
            })),
        ),
        (
            "stats with struct_size 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "struct_size",
            c(Box::new(|| {
                with_cube(false, |g| {
                    // SAFETY: zeroed is a valid value of this plain C struct.
                    let mut st: abgs_grid_stats = unsafe { std::mem::zeroed() };
                    // SAFETY: a writable struct.
                    let r = unsafe { abgs_grid_get_stats(g, &mut st) };
                    assert_eq!(st.vertices, 0, "written despite the error");
                    outcome(r)
                })
            })),
        ),
        (
            "every pointer NULL, every call",
            ABGS_ERR_NULL,
            "is NULL",
            c(Box::new(every_null)),
        ),
        // ---- parameters ----
        (
            "simplify method 7",
            ABGS_ERR_INVALID_ARGUMENT,
            "method = 7",
            c(Box::new(|| simplify_with(|p| p.method = 7))),
        ),
        (
            "simplify struct_size 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "struct_size",
            c(Box::new(|| simplify_with(|p| p.struct_size = 0))),
        ),
        (
            "simplify struct_size garbage",
            ABGS_ERR_INVALID_ARGUMENT,
            "struct_size",
            c(Box::new(|| simplify_with(|p| p.struct_size = 0xFFFF_FFF0))),
        ),
        (
            "simplify t_size NaN",
            ABGS_ERR_NON_FINITE,
            "t_size",
            c(Box::new(|| simplify_with(|p| p.t_size = f64::NAN))),
        ),
        (
            "simplify fraction 2",
            ABGS_ERR_INVALID_ARGUMENT,
            "fraction",
            c(Box::new(|| simplify_with(|p| p.fraction = 2.0))),
        ),
        (
            "simplify tau_d 1e-300",
            ABGS_ERR_INVALID_ARGUMENT,
            "tau_d = 1e-300",
            c(Box::new(|| {
                simplify_with(|p| {
                    p.tau_d = 1e-300;
                    p.max_iterations = 2;
                })
            })),
        ),
        (
            "simplify tau_d -1",
            ABGS_ERR_INVALID_ARGUMENT,
            "tau_d = -1 must be >= 0",
            c(Box::new(|| simplify_with(|p| p.tau_d = -1.0))),
        ),
        (
            "simplify beta 1",
            ABGS_ERR_INVALID_ARGUMENT,
            "beta",
            c(Box::new(|| simplify_with(|p| p.beta = 1.0))),
        ),
        (
            "simplify clearance_fraction NaN",
            ABGS_ERR_NON_FINITE,
            "clearance_fraction",
            c(Box::new(|| {
                simplify_with(|p| p.clearance_fraction = f64::NAN)
            })),
        ),
        (
            "simplify max_iterations 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "max_iterations",
            c(Box::new(|| simplify_with(|p| p.max_iterations = 0))),
        ),
        (
            "progress callback cancels at once",
            ABGS_OK,
            "",
            c(Box::new(|| {
                simplify_with(|p| p.progress = Some(cancel_at_once))
            })),
        ),
        (
            "remesh feature angle 200",
            ABGS_ERR_INVALID_ARGUMENT,
            "feature_angle_deg",
            c(Box::new(|| remesh_with(|p| p.feature_angle_deg = 200.0))),
        ),
        (
            "remesh edge_length inf",
            ABGS_ERR_NON_FINITE,
            "edge_length",
            c(Box::new(|| remesh_with(|p| p.edge_length = f64::INFINITY))),
        ),
        (
            "remesh iterations 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "iterations",
            c(Box::new(|| remesh_with(|p| p.iterations = 0))),
        ),
        (
            "size n_gap -1",
            ABGS_ERR_INVALID_ARGUMENT,
            "n_gap",
            c(Box::new(|| size_with(|p, _| p.n_gap = -1.0))),
        ),
        (
            "size hmin NaN",
            ABGS_ERR_NON_FINITE,
            "hmin",
            c(Box::new(|| size_with(|p, _| p.hmin = f64::NAN))),
        ),
        (
            "size source kind 9",
            ABGS_ERR_INVALID_ARGUMENT,
            "kind 9",
            c(Box::new(|| {
                size_with(|p, s| {
                    p.n_sources = 1;
                    s.kind = 9;
                })
            })),
        ),
        (
            "size source struct_size 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "sources[0]->struct_size",
            c(Box::new(|| {
                size_with(|p, s| {
                    p.n_sources = 1;
                    s.struct_size = 0;
                })
            })),
        ),
        (
            "size sources NULL with a count",
            ABGS_ERR_NULL,
            "sources",
            c(Box::new(|| {
                size_with(|p, _| {
                    p.n_sources = 3;
                })
            })),
        ),
        (
            "size params from a newer header with an unknown field set",
            ABGS_ERR_INVALID_ARGUMENT,
            "does not know",
            c(Box::new(|| {
                with_cube(false, |g| {
                    #[repr(C)]
                    struct Newer {
                        p: abgs_size_params,
                        extra: u64,
                    }
                    // SAFETY: zeroed is a valid value of these plain C structs.
                    let mut n: Newer = unsafe { std::mem::zeroed() };
                    n.p.struct_size = std::mem::size_of::<Newer>() as u32;
                    // SAFETY: writable, struct_size bytes.
                    assert_eq!(unsafe { abgs_size_params_default(&mut n.p) }, ABGS_OK);
                    n.p.struct_size = std::mem::size_of::<Newer>() as u32;
                    n.extra = 1;
                    // SAFETY: struct_size readable bytes.
                    outcome(unsafe { abgs_compute_size(g, &n.p, null_mut()) })
                })
            })),
        ),
        (
            "eval samples 0",
            ABGS_ERR_INVALID_ARGUMENT,
            "samples",
            c(Box::new(|| {
                with_cube(true, |g| {
                    // SAFETY: zeroed is a valid value of these plain C structs.
                    let (mut p, mut e): (abgs_eval_params, abgs_evaluation) =
                        unsafe { (std::mem::zeroed(), std::mem::zeroed()) };
                    p.struct_size = std::mem::size_of_val(&p) as u32;
                    e.struct_size = std::mem::size_of_val(&e) as u32;
                    // SAFETY: writable structs.
                    assert_eq!(unsafe { abgs_eval_params_default(&mut p) }, ABGS_OK);
                    p.samples = 0;
                    // SAFETY: valid grids and structs.
                    outcome(unsafe { abgs_evaluate(g, g, &p, &mut e) })
                })
            })),
        ),
        (
            "gradation beta 0.5",
            ABGS_ERR_INVALID_ARGUMENT,
            "",
            c(Box::new(|| {
                with_cube(true, |g| {
                    // SAFETY: valid grid.
                    outcome(unsafe { abgs_apply_gradation(g, 0.5, 0.0, null_mut()) })
                })
            })),
        ),
        (
            "remesh issue of a grid the remesher did not make",
            ABGS_ERR_INVALID_ARGUMENT,
            "abgs_grid_remesh",
            c(Box::new(|| {
                with_cube(false, |g| {
                    let mut b = [0 as std::ffi::c_char; 1];
                    // SAFETY: a 1-byte buffer.
                    outcome(unsafe { abgs_grid_remesh_issue(g, 0, b.as_mut_ptr(), 1, null_mut()) })
                })
            })),
        ),
        (
            "same arrays at another scale give the same grid",
            ABGS_OK,
            "",
            c(Box::new(move || {
                let (o, g) = from_arrays(&v2, 8, &t2, 12, None);
                let s: Vec<f64> = v2.iter().map(|x| x * 1e15).collect();
                let (o2, g2) = from_arrays(&s, 8, &t2, 12, None);
                assert_eq!((o.status, o2.status), (ABGS_OK, ABGS_OK));
                let mut n = [0usize; 2];
                // SAFETY: valid grids and out-pointers.
                unsafe {
                    abgs_grid_triangle_count(g, &mut n[0]);
                    abgs_grid_triangle_count(g2, &mut n[1]);
                }
                assert_eq!(n[0], n[1]);
                free(g);
                free(g2);
                o
            })),
        ),
        // ---- .abgs binary grids (abgs_grid_deserialize, abgs_grid_load) ----
        (
            "abgs file with one byte changed",
            ABGS_ERR_PARSE,
            "checksum",
            c(Box::new(|| {
                load_bytes("abgs", &cube_abgs_with(|b| b[200] ^= 1, false))
            })),
        ),
        (
            "abgs file truncated",
            ABGS_ERR_PARSE,
            "truncated",
            c(Box::new(|| {
                let b = cube_abgs();
                load_bytes("abgs", &b[..b.len() - 9])
            })),
        ),
        (
            "abgs buffer of format version 2",
            ABGS_ERR_UNSUPPORTED_FORMAT,
            "version 2",
            c(Box::new(|| {
                deserialize(&cube_abgs_with(|b| b[8] = 2, true))
            })),
        ),
        (
            "abgs buffer written big-endian",
            ABGS_ERR_UNSUPPORTED_FORMAT,
            "big-endian",
            c(Box::new(|| {
                deserialize(&cube_abgs_with(
                    |b| b[12..16].copy_from_slice(&[10, 11, 12, 13]),
                    true,
                ))
            })),
        ),
        (
            "abgs buffer claiming 2^32-1 vertices (memory bomb)",
            ABGS_ERR_PARSE,
            "do not fit",
            c(Box::new(|| {
                deserialize(&cube_abgs_with(
                    |b| b[24..32].copy_from_slice(&(u32::MAX as u64).to_le_bytes()),
                    true,
                ))
            })),
        ),
        (
            "abgs buffer with a NaN coordinate behind a valid checksum",
            ABGS_ERR_NON_FINITE,
            "vertex 1",
            c(Box::new(|| {
                deserialize(&cube_abgs_with(
                    |b| b[128 + 24..128 + 32].copy_from_slice(&f64::NAN.to_le_bytes()),
                    true,
                ))
            })),
        ),
        (
            "abgs buffer that is an STL",
            ABGS_ERR_PARSE,
            "not an abgs grid",
            c(Box::new(|| deserialize(&binary_stl(2, 2)))),
        ),
        (
            "abgs serialise into a buffer one byte short",
            ABGS_ERR_BUFFER_TOO_SMALL,
            "needed",
            c(Box::new(|| {
                with_cube(true, |g| {
                    let n = cube_abgs().len();
                    let mut b = vec![7u8; n - 1];
                    let mut len = 0usize;
                    // SAFETY: a valid grid, a buffer of n - 1 bytes.
                    let st =
                        unsafe { abgs_grid_serialize(g, b.as_mut_ptr().cast(), n - 1, &mut len) };
                    assert_eq!(len, n, "the size needed is reported");
                    assert!(b.iter().all(|&x| x == 7), "nothing written");
                    outcome(st)
                })
            })),
        ),
    ]
}

trait TapMkdir {
    fn tap_mkdir(self) -> Self;
}
impl TapMkdir for PathBuf {
    fn tap_mkdir(self) -> Self {
        std::fs::create_dir_all(&self).unwrap();
        self
    }
}

/// Every export with each of its pointer arguments NULL in turn: ABGS_ERR_NULL
/// each time (the outcome returned is the last one; each is checked here).
fn every_null() -> Outcome {
    let (v, t) = cube();
    let (_, g) = from_arrays(&v, 8, &t, 12, Some(&[0.3; 8]));
    let p = [0.5f64; 3];
    let (mut h, mut hint, mut n) = (0.0, 0u32, 0usize);
    let mut out = null_mut();
    let path = CString::new("x.vtk").unwrap();
    let n_ = null_mut::<f64>();
    // SAFETY: every non-NULL pointer is valid; the NULL ones are reported.
    let calls: Vec<(&str, abgs_status)> = unsafe {
        vec![
            ("query grid", abgs_query_size(null(), p.as_ptr(), &mut h)),
            ("query out", abgs_query_size(g, p.as_ptr(), n_)),
            (
                "hinted hint",
                abgs_query_size_hinted(g, p.as_ptr(), null_mut(), &mut h),
            ),
            (
                "hinted point",
                abgs_query_size_hinted(g, null(), &mut hint, &mut h),
            ),
            ("batch points", abgs_query_sizes(g, null(), 1, &mut h)),
            ("batch out", abgs_query_sizes(g, p.as_ptr(), 1, n_)),
            ("volume out", abgs_query_size_volume(g, p.as_ptr(), 1.2, n_)),
            (
                "volume batch points",
                abgs_query_sizes_volume(g, null(), 1, 1.2, &mut h),
            ),
            (
                "closest out",
                abgs_query_closest(g, p.as_ptr(), 0, null_mut()),
            ),
            ("load path", abgs_grid_load(null(), &mut out)),
            ("load out", abgs_grid_load(path.as_ptr(), null_mut())),
            ("save grid", abgs_grid_save(null(), path.as_ptr())),
            ("save path", abgs_grid_save(g, null())),
            (
                "serialize grid",
                abgs_grid_serialize(null(), null_mut(), 0, &mut n),
            ),
            (
                "serialize len",
                abgs_grid_serialize(g, null_mut(), 0, null_mut()),
            ),
            (
                "serialize buf",
                abgs_grid_serialize(g, null_mut(), 10, &mut n),
            ),
            (
                "deserialize buf",
                abgs_grid_deserialize(null(), 10, &mut out),
            ),
            (
                "deserialize out",
                abgs_grid_deserialize(p.as_ptr().cast(), 24, null_mut()),
            ),
            ("set_sizes sizes", abgs_grid_set_sizes(g, null(), 8)),
            ("stats out", abgs_grid_get_stats(g, null_mut())),
            ("vertex count out", abgs_grid_vertex_count(g, null_mut())),
            ("triangle count", abgs_grid_triangle_count(null(), &mut n)),
            ("copy vertices", abgs_grid_copy_vertices(g, n_, 24)),
            (
                "copy triangles",
                abgs_grid_copy_triangles(g, null_mut(), 36),
            ),
            ("copy sizes", abgs_grid_copy_sizes(g, n_, 8)),
            ("edge count", abgs_grid_edge_count(g, null_mut())),
            ("copy edges", abgs_grid_copy_edges(g, null_mut(), 36)),
            ("lbo outs", abgs_lbo(g, n_, 0, n_, 0)),
            (
                "compute_size grid",
                abgs_compute_size(null_mut(), null(), null_mut()),
            ),
            (
                "gradation grid",
                abgs_apply_gradation(null_mut(), 1.2, 0.0, null_mut()),
            ),
            (
                "simplify out",
                abgs_simplify(g, null(), null_mut(), null_mut()),
            ),
            (
                "simplify grid",
                abgs_simplify(null(), null(), &mut out, null_mut()),
            ),
            (
                "edge scores grid",
                abgs_edge_scores(null(), null(), n_, n_, null_mut(), n_, 0),
            ),
            (
                "iteration out",
                abgs_grid_simplify_iteration(g, 0, null_mut()),
            ),
            (
                "remesh input",
                abgs_grid_remesh(null(), null(), null(), &mut out, null_mut()),
            ),
            (
                "remesh out",
                abgs_grid_remesh(g, null(), null(), null_mut(), null_mut()),
            ),
            (
                "feature edge count",
                abgs_grid_remesh_feature_edge_count(null(), &mut n),
            ),
            (
                "evaluate reference",
                abgs_evaluate(null(), g, null(), null_mut()),
            ),
            ("hausdorff out", abgs_hausdorff(g, g, 10, 1, n_)),
            (
                "directed from",
                abgs_hausdorff_directed(null(), g, 10, 1, &mut h),
            ),
            ("params default", abgs_simplify_params_default(null_mut())),
            ("size default", abgs_size_params_default(null_mut())),
            ("remesh default", abgs_remesh_params_default(null_mut())),
            ("eval default", abgs_eval_params_default(null_mut())),
        ]
    };
    for (what, st) in &calls {
        assert_eq!(*st, ABGS_ERR_NULL, "{what}");
    }
    free(g);
    // SAFETY: a NULL grid is accepted by free.
    assert_eq!(unsafe { abgs_grid_free(null_mut()) }, ABGS_OK);
    let status = calls.last().unwrap().1;
    // SAFETY: a NULL path is reported.
    unsafe { abgs_grid_load(null(), &mut out) };
    Outcome {
        status,
        message: last_message(),
    }
}

#[test]
fn bad_input_matrix() {
    let cases = cases();
    assert!(cases.len() >= 40, "{} cases", cases.len());
    let mut failures = Vec::new();
    let mut table = String::from("| case | status | message |\n|---|---|---|\n");
    for (name, expect, needle, run) in &cases {
        let o = run();
        table += &format!(
            "| {name} | {} | {} |\n",
            o.status.name().to_str().unwrap(),
            o.message.replace('|', "/").replace('\n', " ")
        );
        if o.status != *expect {
            failures.push(format!(
                "{name}: {:?}, expected {expect:?} ({})",
                o.status, o.message
            ));
        } else if *expect != ABGS_OK
            && (!o.message.starts_with("abgs_") || !o.message.contains(needle))
        {
            failures.push(format!(
                "{name}: message {:?} does not name {needle:?}",
                o.message
            ));
        }
    }
    println!("{table}");
    if let Ok(path) = std::env::var("ABGS_BAD_INPUT_TABLE") {
        std::fs::write(path, &table).unwrap();
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
