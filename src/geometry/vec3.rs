//! Free functions on `[f64; 3]` (kept as plain arrays so grids are flat, `Copy`
//! and FFI-friendly).

/// `a + b`.
#[inline(always)]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline(always)]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
#[inline(always)]
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
#[inline(always)]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
#[inline(always)]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Squared Euclidean norm.
#[inline(always)]
pub fn norm2(a: [f64; 3]) -> f64 {
    dot(a, a)
}

/// Euclidean norm.
#[inline(always)]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Squared distance between two points.
#[inline(always)]
pub fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm2(sub(a, b))
}

/// `a + t (b - a)`.
#[inline(always)]
pub fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    add(a, scale(sub(b, a), t))
}

/// True when all three coordinates are finite.
#[inline(always)]
pub fn is_finite3(a: [f64; 3]) -> bool {
    a[0].is_finite() && a[1].is_finite() && a[2].is_finite()
}

/// Largest coordinate magnitude accepted for grid vertices and query points.
///
/// Within `±MAX_COORDINATE` every difference of two points and every squared
/// distance stays finite (`3 · (2·10^150)^2 ≈ 1.2·10^301 < f64::MAX`), which the
/// closest-point search, the degeneracy test and the volume bound rely on. Beyond
/// it squared distances overflow to infinity and a search can no longer tell
/// triangles apart (fuzzing found grids that could not answer a query at their own
/// vertices), so such values are refused like non-finite ones.
pub const MAX_COORDINATE: f64 = 1e150;

/// True when all three coordinates are finite and at most [`MAX_COORDINATE`] in
/// magnitude (the check applied to grid vertices and query points).
#[inline(always)]
pub fn is_coordinate3(a: [f64; 3]) -> bool {
    a[0].abs() <= MAX_COORDINATE && a[1].abs() <= MAX_COORDINATE && a[2].abs() <= MAX_COORDINATE
}
