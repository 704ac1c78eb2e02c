//! Shared code of the abgs fuzz targets (see `README.md`).
//!
//! The readers are path-based, so each file target writes its input to a scratch
//! file of the right extension (one per process, overwritten for every input) and
//! calls [`abgs::Grid::load`]: reading, welding, validation and the BVH are fuzzed
//! together. A load must end in a grid that satisfies [`check_grid`] or in an
//! error; anything else (a panic, an abort, a hang, a huge allocation) is a finding.
//!
//! Two per-input costs that have nothing to do with abgs are avoided (together
//! they more than halved the executions per second, see `README.md`):
//! - the scratch file lives in `/dev/shm` (memory) when that exists, else under
//!   [`std::env::temp_dir`]: ext4 flushes a file that is truncated and rewritten
//!   to disk on close, which made every input wait for the disk;
//! - rayon's global pool is made of the fuzzing thread alone ([`setup`]), so the
//!   library's parallel loops run inline instead of waking (and spinning) worker
//!   threads for every input. The code paths are the same; only the scheduling
//!   differs.
//!
//! Without a sanitizer libFuzzer cannot see single allocations (its
//! `-malloc_limit_mb` needs the sanitizer's malloc hooks), and Linux hands out
//! untouched memory lazily, so a `Vec::with_capacity(10^9)` trusted from a header
//! would pass unnoticed under `-rss_limit_mb`. The global allocator of the targets
//! ([`alloc_limit`]) therefore aborts on any single request over 2 GiB.

pub mod arrays;
pub mod serialized;

mod alloc_limit;

use abgs::Grid;
use std::path::PathBuf;
use std::sync::OnceLock;

/// Once per process: rayon's global pool becomes the calling thread alone.
pub fn setup() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // An error means the pool already exists (nothing to do then).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .use_current_thread()
            .build_global();
    });
}

/// The scratch file of this process with extension `ext`.
pub fn scratch(ext: &str) -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    let dir = DIR.get_or_init(|| {
        let shm = PathBuf::from("/dev/shm");
        if shm.is_dir() {
            shm
        } else {
            std::env::temp_dir()
        }
    });
    dir.join(format!("abgs-fuzz-{}.{ext}", std::process::id()))
}

/// Whether `ABGS_FUZZ_VERBOSE` is set: then each outcome is printed (to check seeds).
pub(crate) fn verbose() -> bool {
    static V: OnceLock<bool> = OnceLock::new();
    *V.get_or_init(|| std::env::var_os("ABGS_FUZZ_VERBOSE").is_some())
}

/// Writes `bytes` to the scratch file `.ext`, loads it and checks the outcome.
pub fn load(ext: &str, bytes: &[u8]) -> Option<Grid> {
    setup();
    let path = scratch(ext);
    std::fs::write(&path, bytes).expect("cannot write the scratch file");
    load_path(&path)
}

/// Medit: `mesh NUL sol` (the `.sol` beside the `.mesh` only when a NUL is present).
pub fn load_medit(data: &[u8]) -> Option<Grid> {
    setup();
    let mesh = scratch("mesh");
    let sol = scratch("sol");
    let (m, s) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], Some(&data[i + 1..])),
        None => (data, None),
    };
    std::fs::write(&mesh, m).expect("cannot write the scratch file");
    match s {
        Some(s) => std::fs::write(&sol, s).expect("cannot write the scratch file"),
        None => {
            let _ = std::fs::remove_file(&sol);
        }
    }
    load_path(&mesh)
}

fn load_path(path: &std::path::Path) -> Option<Grid> {
    match Grid::load(path) {
        Ok(g) => {
            if verbose() {
                eprintln!(
                    "loaded: {} vertices, {} triangles, sizes: {}",
                    g.vertices().len(),
                    g.triangles().len(),
                    g.sizes().is_some()
                );
            }
            check_grid(&g);
            Some(g)
        }
        Err(e) => {
            let msg = e.to_string();
            if verbose() {
                eprintln!("error: {msg}");
            }
            assert!(!msg.is_empty());
            None
        }
    }
}

/// The invariants of every built grid: at least one triangle, indices in range,
/// finite coordinates, valid sizes, and a closest-point query that answers.
pub fn check_grid(g: &Grid) {
    let nv = g.vertices().len();
    assert!(!g.triangles().is_empty(), "a grid without triangles");
    assert!(
        g.triangles().iter().flatten().all(|&v| (v as usize) < nv),
        "a triangle index out of range"
    );
    assert!(
        g.vertices().iter().flatten().all(|c| c.is_finite()),
        "a non-finite coordinate"
    );
    if let Some(s) = g.sizes() {
        assert_eq!(s.len(), nv, "sizes of the wrong length");
        assert!(
            s.iter().all(|&x| x.is_finite() && x > 0.0),
            "an invalid size"
        );
    }
    let b = g.bbox();
    let centre = [0, 1, 2].map(|i| 0.5 * b.min[i] + 0.5 * b.max[i]);
    for p in [centre, g.vertices()[g.triangles()[0][0] as usize]] {
        let hit = g.closest(p, None).unwrap_or_else(|e| {
            panic!(
                "closest at {p:?} failed: {e}; vertices {:?}, triangles {:?}",
                g.vertices(),
                g.triangles()
            )
        });
        assert!((hit.triangle as usize) < g.triangles().len());
        if g.sizes().is_some() {
            assert!(
                hit.size.is_finite() && hit.size > 0.0,
                "size {} at {p:?}",
                hit.size
            );
        }
    }
}
