use super::field::{Source, SourceField};
use crate::geometry::closest_point_triangle;
use crate::test_shapes::rng;

#[test]
fn source_field_equals_brute_force() {
    let mut seed = 7;
    let p = |s: &mut u64| [rng(s) * 10.0, rng(s) * 10.0, rng(s) * 10.0];
    let mut sources: Vec<Source> = Vec::new();
    for i in 0..300 {
        let a = p(&mut seed);
        let b = p(&mut seed);
        let c = p(&mut seed);
        // Points, segments and triangles.
        let prim = match i % 3 {
            0 => [a; 3],
            1 => [a, b, b],
            _ => [a, b, c],
        };
        sources.push((prim, 0.1 + rng(&mut seed)));
    }
    sources.push(([[0.0; 3]; 3], f64::INFINITY)); // ignored
    let slope = 0.3;
    let field = SourceField::new(&sources, slope);
    for _ in 0..500 {
        let q = [
            rng(&mut seed) * 14.0 - 2.0,
            rng(&mut seed) * 14.0 - 2.0,
            rng(&mut seed) * 14.0 - 2.0,
        ];
        let brute = sources
            .iter()
            .filter(|s| s.1.is_finite())
            .map(|(t, h)| h + slope * closest_point_triangle(q, t[0], t[1], t[2]).dist2.sqrt())
            .fold(f64::INFINITY, f64::min);
        assert_eq!(field.eval(q), brute, "at {q:?}");
    }
    assert_eq!(SourceField::new(&[], slope).eval([0.0; 3]), f64::INFINITY);
}
