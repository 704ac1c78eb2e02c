//! The `arrays_query` target: `abgs_grid_from_arrays` on arbitrary numbers, then
//! a few calls of every query kind, `abgs_grid_set_sizes` and the copy-out
//! accessors, each through the C ABI. Every call must return a status (a panic
//! aborts the fuzzer before the panic boundary could catch it, and
//! `ABGS_ERR_INTERNAL` is refused too); a grid that was built must answer finite,
//! positive sizes at finite points, the hinted and batch answers must equal the
//! single query's bit for bit, and the copies must match what was given.

use abgs::ffi::*;
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use std::ptr::{null, null_mut};

/// Values worth trying that random bits seldom give.
const SPECIAL: [f64; 19] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    f64::MAX,
    f64::MIN,
    f64::MIN_POSITIVE,
    5e-324,
    1e300,
    -1e300,
    1e-300,
    1e150,
    1.000_000_000_000_000_2e150,
    1e-150,
    f64::EPSILON,
    1.0 + f64::EPSILON,
    1e16,
    0.1,
];

/// A number: mostly small, sometimes raw bits or a special value.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub enum Num {
    /// A small integer.
    Small(i8),
    /// `m · 2^-e`, e in 0..64.
    Frac(i16, u8),
    /// Any bits.
    Raw(f64),
    /// One of [`SPECIAL`].
    Special(u8),
}

impl Num {
    /// The value.
    pub fn get(self) -> f64 {
        match self {
            Num::Small(i) => i as f64,
            Num::Frac(m, e) => m as f64 * 2f64.powi(-((e % 64) as i32)),
            Num::Raw(x) => x,
            Num::Special(k) => SPECIAL[k as usize % SPECIAL.len()],
        }
    }
}

/// A vertex index: mostly small (in range or just past it), sometimes any u32.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub enum Idx {
    /// 0..=255.
    Small(u8),
    /// Any value.
    Raw(u32),
}

impl Idx {
    fn get(self) -> u32 {
        match self {
            Idx::Small(i) => i as u32,
            Idx::Raw(i) => i,
        }
    }
}

/// Sizes: `values` cycled to the vertex count plus `delta` (when |delta| ≤ 2).
#[derive(Debug, Clone, Arbitrary)]
pub struct Sizes {
    values: Vec<Num>,
    delta: i8,
}

impl Sizes {
    fn make(&self, nv: usize) -> Vec<f64> {
        let n = if self.delta.unsigned_abs() <= 2 {
            (nv as isize + self.delta as isize).max(0) as usize
        } else {
            nv
        };
        if self.values.is_empty() {
            return vec![1.0; n];
        }
        (0..n)
            .map(|i| self.values[i % self.values.len()].get())
            .collect()
    }
}

/// One call on the grid.
#[derive(Debug, Clone, Arbitrary)]
pub enum Call {
    /// `abgs_query_size` (and `abgs_query_size_hinted` with no hint, compared).
    Size([Num; 3]),
    /// `abgs_query_size_hinted` with any hint.
    Hinted([Num; 3], u32),
    /// `abgs_query_sizes` on up to 64 points.
    Sizes(Vec<[Num; 3]>),
    /// `abgs_query_size_volume`.
    Volume([Num; 3], Num),
    /// `abgs_query_sizes_volume` on up to 64 points.
    SizesVolume(Vec<[Num; 3]>, Num),
    /// `abgs_grid_set_sizes`.
    SetSizes(Sizes),
    /// The three `abgs_grid_copy_*` calls, with room for `3n + delta` items.
    Copy(i8),
    /// A call with one NULL pointer (which one: the byte).
    Null(u8),
}

/// The whole input.
#[derive(Debug, Clone, Arbitrary)]
pub struct Input {
    vertices: Vec<[Num; 3]>,
    triangles: Vec<[Idx; 3]>,
    sizes: Option<Sizes>,
    calls: Vec<Call>,
}

fn ok(st: abgs_status, what: &str) {
    assert_ne!(st, abgs_status::ABGS_ERR_INTERNAL, "{what}: internal error");
}

/// Whether `p` is a point that abgs must accept (finite, within ±1e150).
fn finite3(p: [f64; 3]) -> bool {
    abgs::geometry::is_coordinate3(p)
}

/// State of the grid under test, mirrored on the Rust side.
struct Model {
    grid: *mut abgs_grid,
    nv: usize,
    nt: usize,
    xyz: Vec<f64>,
    sizes: Option<Vec<f64>>,
}

/// Runs one input.
pub fn run(input: &Input) {
    crate::setup();
    let xyz: Vec<f64> = input.vertices.iter().flatten().map(|n| n.get()).collect();
    let tris: Vec<u32> = input.triangles.iter().flatten().map(|i| i.get()).collect();
    let nv = input.vertices.len();
    let nt = input.triangles.len();
    let sizes = input.sizes.as_ref().map(|s| s.make(nv));
    let mut grid: *mut abgs_grid = null_mut();
    // SAFETY: the arrays hold 3nv, 3nt and (when given) sizes.len() items; a short
    // size array is passed as NULL (the C contract wants nv values).
    let st = unsafe {
        abgs_grid_from_arrays(
            if xyz.is_empty() { null() } else { xyz.as_ptr() },
            nv,
            if tris.is_empty() {
                null()
            } else {
                tris.as_ptr()
            },
            nt,
            match &sizes {
                Some(s) if s.len() >= nv && nv > 0 => s.as_ptr(),
                _ => null(),
            },
            &mut grid,
        )
    };
    ok(st, "abgs_grid_from_arrays");
    if crate::verbose() {
        eprintln!(
            "from_arrays: {st:?} ({nv} vertices, {nt} triangles), {} calls",
            input.calls.len().min(16)
        );
    }
    let sizes = sizes.filter(|s| s.len() >= nv && nv > 0).map(|mut s| {
        s.truncate(nv);
        s
    });
    if st != abgs_status::ABGS_OK {
        assert!(grid.is_null(), "a failed build returned a grid");
        return;
    }
    assert!(!grid.is_null());
    assert!(
        xyz.chunks_exact(3).all(|p| finite3([p[0], p[1], p[2]])),
        "built with a coordinate that is not finite or beyond ±1e150"
    );
    assert!(
        tris.iter().all(|&i| (i as usize) < nv),
        "built with a bad index"
    );
    if let Some(s) = &sizes {
        assert!(
            s.iter().all(|&x| x.is_finite() && x > 0.0),
            "built with a bad size"
        );
    }
    let mut m = Model {
        grid,
        nv,
        nt,
        xyz,
        sizes,
    };
    for call in input.calls.iter().take(16) {
        m.call(call);
    }
    // SAFETY: a grid from abgs_grid_from_arrays, freed once.
    let st = unsafe { abgs_grid_free(m.grid) };
    assert_eq!(st, abgs_status::ABGS_OK);
}

impl Model {
    fn size(&self, p: [f64; 3]) -> (abgs_status, f64) {
        let mut out = f64::NAN;
        // SAFETY: a live grid, three doubles, one writable double.
        let st = unsafe { abgs_query_size(self.grid, p.as_ptr(), &mut out) };
        ok(st, "abgs_query_size");
        let want = match (&self.sizes, finite3(p)) {
            (None, _) => abgs_status::ABGS_ERR_NO_SIZES,
            (Some(_), false) => abgs_status::ABGS_ERR_NON_FINITE,
            (Some(_), true) => abgs_status::ABGS_OK,
        };
        assert_eq!(st, want, "abgs_query_size at {p:?}");
        if st == abgs_status::ABGS_OK {
            assert!(out.is_finite() && out > 0.0, "size {out} at {p:?}");
        }
        (st, out)
    }

    fn hinted(&self, p: [f64; 3], hint: u32) {
        let (st0, want) = self.size(p);
        let mut h = hint;
        let mut out = f64::NAN;
        // SAFETY: a live grid, three doubles, writable hint and output.
        let st = unsafe { abgs_query_size_hinted(self.grid, p.as_ptr(), &mut h, &mut out) };
        ok(st, "abgs_query_size_hinted");
        assert_eq!(st, st0, "hinted and plain statuses differ at {p:?}");
        if st == abgs_status::ABGS_OK {
            assert_eq!(
                out.to_bits(),
                want.to_bits(),
                "hinted {out} != {want} at {p:?}"
            );
            // The new hint names a triangle: querying again from it gives the same.
            let mut out2 = f64::NAN;
            // SAFETY: as above.
            let st = unsafe { abgs_query_size_hinted(self.grid, p.as_ptr(), &mut h, &mut out2) };
            assert_eq!(st, abgs_status::ABGS_OK);
            assert_eq!(out2.to_bits(), want.to_bits());
        }
    }

    fn batch(&self, pts: &[[Num; 3]], beta: Option<f64>) {
        let pts: Vec<[f64; 3]> = pts.iter().take(64).map(|p| p.map(Num::get)).collect();
        let flat: Vec<f64> = pts.iter().flatten().copied().collect();
        let mut out = vec![f64::NAN; pts.len()];
        let (pp, op) = if pts.is_empty() {
            (null(), null_mut())
        } else {
            (flat.as_ptr(), out.as_mut_ptr())
        };
        // SAFETY: 3n doubles in, n doubles out, not overlapping.
        let st = unsafe {
            match beta {
                None => abgs_query_sizes(self.grid, pp, pts.len(), op),
                Some(b) => abgs_query_sizes_volume(self.grid, pp, pts.len(), b, op),
            }
        };
        ok(st, "batch query");
        let beta_ok = beta.is_none_or(|b| b.is_finite() && b > 1.0);
        let all_finite = pts.iter().all(|p| finite3(*p));
        if self.sizes.is_some() && beta_ok && all_finite {
            assert_eq!(st, abgs_status::ABGS_OK, "batch on {pts:?}, beta {beta:?}");
            for (p, &o) in pts.iter().zip(&out) {
                let single = match beta {
                    None => self.size(*p).1,
                    Some(b) => self.volume(*p, b).1,
                };
                assert_eq!(
                    o.to_bits(),
                    single.to_bits(),
                    "batch {o} != single {single} at {p:?}"
                );
            }
        } else {
            assert_ne!(st, abgs_status::ABGS_OK, "batch on {pts:?}, beta {beta:?}");
            assert!(
                out.iter().all(|o| o.is_nan()),
                "a failed batch wrote results"
            );
        }
    }

    fn volume(&self, p: [f64; 3], beta: f64) -> (abgs_status, f64) {
        let mut out = f64::NAN;
        // SAFETY: a live grid, three doubles, one writable double.
        let st = unsafe { abgs_query_size_volume(self.grid, p.as_ptr(), beta, &mut out) };
        ok(st, "abgs_query_size_volume");
        if self.sizes.is_some() && finite3(p) && beta.is_finite() && beta > 1.0 {
            assert_eq!(st, abgs_status::ABGS_OK, "volume at {p:?}, beta {beta}");
            assert!(
                out.is_finite() && out > 0.0,
                "volume size {out} at {p:?}, beta {beta}"
            );
        } else {
            assert_ne!(st, abgs_status::ABGS_OK, "volume at {p:?}, beta {beta}");
        }
        (st, out)
    }

    fn set_sizes(&mut self, s: &Sizes) {
        let v = s.make(self.nv);
        // SAFETY: a live grid, v.len() doubles.
        let st = unsafe { abgs_grid_set_sizes(self.grid, v.as_ptr(), v.len()) };
        ok(st, "abgs_grid_set_sizes");
        let valid = v.len() == self.nv && v.iter().all(|&x| x.is_finite() && x > 0.0);
        assert_eq!(st == abgs_status::ABGS_OK, valid, "set_sizes {v:?}: {st:?}");
        if valid {
            self.sizes = Some(v);
        }
    }

    fn copy(&self, delta: i8) {
        let d = delta as isize % 4;
        let room = |n: usize| (n as isize + d).max(0) as usize;
        let mut xyz = vec![f64::NAN; room(3 * self.nv)];
        // SAFETY: a live grid, room for xyz.len() doubles.
        let st = unsafe { abgs_grid_copy_vertices(self.grid, xyz.as_mut_ptr(), xyz.len()) };
        ok(st, "abgs_grid_copy_vertices");
        if d >= 0 {
            assert_eq!(st, abgs_status::ABGS_OK);
            let same = xyz
                .iter()
                .zip(&self.xyz)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "copied vertices differ from the input");
        } else {
            assert_eq!(st, abgs_status::ABGS_ERR_BUFFER_TOO_SMALL);
        }
        // Triangles: at most as many as given; unwritten slots keep u32::MAX.
        let mut t = vec![u32::MAX; room(3 * self.nt).max(3 * self.nt)];
        // SAFETY: a live grid, room for t.len() indices.
        let st = unsafe { abgs_grid_copy_triangles(self.grid, t.as_mut_ptr(), t.len()) };
        ok(st, "abgs_grid_copy_triangles");
        if st == abgs_status::ABGS_OK {
            let n = t.iter().position(|&i| i == u32::MAX).unwrap_or(t.len());
            assert!(n >= 3 && n % 3 == 0, "{n} triangle indices copied");
            assert!(t[..n].iter().all(|&i| (i as usize) < self.nv));
        }
        let mut zero = [0u32; 1];
        // SAFETY: room for 0 indices.
        let st = unsafe { abgs_grid_copy_triangles(self.grid, zero.as_mut_ptr(), 0) };
        assert_eq!(st, abgs_status::ABGS_ERR_BUFFER_TOO_SMALL);
        let mut s = vec![f64::NAN; room(self.nv)];
        // SAFETY: a live grid, room for s.len() doubles.
        let st = unsafe { abgs_grid_copy_sizes(self.grid, s.as_mut_ptr(), s.len()) };
        ok(st, "abgs_grid_copy_sizes");
        match &self.sizes {
            None => assert_eq!(st, abgs_status::ABGS_ERR_NO_SIZES),
            Some(_) if d < 0 => assert_eq!(st, abgs_status::ABGS_ERR_BUFFER_TOO_SMALL),
            Some(want) => {
                assert_eq!(st, abgs_status::ABGS_OK);
                let same = s.iter().zip(want).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "copied sizes differ from those set");
            }
        }
    }

    fn null(&self, which: u8) {
        let p = [0.0f64; 3];
        let mut out = 0.0;
        // SAFETY: every non-NULL pointer is valid; the NULL one must be reported.
        let st = unsafe {
            match which % 8 {
                0 => abgs_query_size(null(), p.as_ptr(), &mut out),
                1 => abgs_query_size(self.grid, null(), &mut out),
                2 => abgs_query_size(self.grid, p.as_ptr(), null_mut()),
                3 => abgs_query_size_hinted(self.grid, p.as_ptr(), null_mut(), &mut out),
                4 => abgs_query_sizes(self.grid, null(), 1, &mut out),
                5 => abgs_query_size_volume(self.grid, null(), 1.5, &mut out),
                6 => abgs_grid_set_sizes(self.grid, null(), self.nv),
                _ => abgs_grid_copy_vertices(self.grid, null_mut(), 3 * self.nv),
            }
        };
        assert_eq!(st, abgs_status::ABGS_ERR_NULL, "NULL case {}", which % 8);
    }

    fn call(&mut self, c: &Call) {
        match c {
            Call::Size(p) => self.hinted(p.map(Num::get), ABGS_NO_HINT),
            Call::Hinted(p, h) => self.hinted(p.map(Num::get), *h),
            Call::Sizes(pts) => self.batch(pts, None),
            Call::Volume(p, b) => {
                self.volume(p.map(Num::get), b.get());
            }
            Call::SizesVolume(pts, b) => self.batch(pts, Some(b.get())),
            Call::SetSizes(s) => self.set_sizes(s),
            Call::Copy(d) => self.copy(*d),
            Call::Null(w) => self.null(*w),
        }
    }
}
