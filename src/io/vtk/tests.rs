//! Tests of the parent module.

use super::*;
use crate::io::off::tests::{same_bits, sample, TempPath};

/// Whether two array lists match by name and bits.
pub(super) fn same_arrays(a: &[PointArray], b: &[PointArray]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.name == y.name
                && x.values.len() == y.values.len()
                && x.values
                    .iter()
                    .zip(&y.values)
                    .all(|(p, q)| p.to_bits() == q.to_bits())
        })
}

/// [`sample`] with a second array whose name needs escaping.
pub(super) fn sample2() -> SurfaceData {
    let mut d = sample();
    d.point_data.push(PointArray {
        name: "my field %".into(),
        values: vec![1.0, 2.0, 3.0, -4.5],
    });
    d
}

#[test]
fn legacy_round_trip() {
    let t = TempPath::new("rt.vtk");
    let d = sample2();
    write_legacy(&t.0, &d).unwrap();
    let r = read_legacy(&t.0).unwrap();
    assert!(same_bits(&r.vertices, &d.vertices));
    assert_eq!(r.triangles, d.triangles);
    assert!(
        same_arrays(&r.point_data, &d.point_data),
        "{:?}",
        r.point_data
    );
}

const V51: &str = "# vtk DataFile Version 5.1\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n\
    POINTS 5 float\n0 0 0 1 0 0 1 1 0\n0 1 0 2 2 2\nMETADATA\nINFORMATION 0\n\n\
    CELLS 4 8\nOFFSETS vtktypeint64\n0 3 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 4 0 1 2 3\n\
    CELL_TYPES 3\n5\n1\n9\nCELL_DATA 3\nSCALARS c int 1\nLOOKUP_TABLE default\n1 2 3\n\
    POINT_DATA 5\nSCALARS size float\nLOOKUP_TABLE default\n1 2 3 4 5\n\
    VECTORS v double\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n\
    FIELD FieldData 2\nh 1 5 double\n5 4 3 2 1\nrgb 3 5 float\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";

#[test]
fn legacy_51_quads_and_fields() {
    let d = parse_legacy(Path::new("x.vtk"), V51.as_bytes()).unwrap();
    assert_eq!(d.vertices.len(), 5);
    assert_eq!(d.triangles, vec![[0, 1, 2], [0, 1, 2], [0, 2, 3]]);
    let names: Vec<_> = d.point_data.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["size", "h"]);
    assert_eq!(d.point_array("h").unwrap(), [5.0, 4.0, 3.0, 2.0, 1.0]);
}

#[test]
fn legacy_binary_polydata() {
    let mut b =
        b"# vtk DataFile Version 3.0\nbin\nBINARY\nDATASET POLYDATA\nPOINTS 4 float\n".to_vec();
    for x in [0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.] {
        b.extend(x.to_be_bytes());
    }
    b.extend(b"\nPOLYGONS 1 5\n");
    for i in [4i32, 0, 1, 2, 3] {
        b.extend(i.to_be_bytes());
    }
    b.extend(b"\nLINES 1 3\n");
    for i in [2i32, 0, 1] {
        b.extend(i.to_be_bytes());
    }
    b.extend(b"\nPOINT_DATA 4\nSCALARS size double 1\nLOOKUP_TABLE default\n");
    for x in [0.5f64, 0.25, 0.125, 1.0 / 3.0] {
        b.extend(x.to_be_bytes());
    }
    b.push(b'\n');
    let d = parse_legacy(Path::new("x.vtk"), &b).unwrap();
    assert_eq!(d.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(
        d.point_array("size").unwrap(),
        [0.5, 0.25, 0.125, 1.0 / 3.0]
    );
    let truncated = &b[..b.len() - 12];
    assert!(parse_legacy(Path::new("x.vtk"), truncated).is_err());
}

#[test]
fn legacy_malformed() {
    let ok = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 3 double\n\
              0 0 0 1 0 0 0 1 0\nCELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n";
    assert_eq!(
        parse_legacy(Path::new("x.vtk"), ok.as_bytes())
            .unwrap()
            .triangles
            .len(),
        1
    );
    for text in [
        String::new(),
        "garbage".into(),
        ok.replace("3 0 1 2", "3 0 1 3"),
        ok.replace("3 0 1 2", "3 0 1 -2"),
        ok.replace("3 0 1 2", "9 0 1 2"),
        ok.replace("CELL_TYPES 1\n5\n", ""),
        ok.replace("CELL_TYPES 1", "CELL_TYPES 2"),
        ok.replace("1 0 0 0 1 0", "1 0 0 0 x 0"),
        ok.replace("POINTS 3", "POINTS 99999999999999999"),
        ok.replace("UNSTRUCTURED_GRID", "STRUCTURED_POINTS"),
        ok.replace("ASCII", "BINARY"),
        format!("{ok}POINT_DATA 2\n"),
        format!("{ok}POINT_DATA 3\nSCALARS s float\nLOOKUP_TABLE default\n1 2\n"),
        format!("{ok}BOGUS 1\n"),
        V51.replace("0 3 4 8", "0 3 9 8"),
    ] {
        assert!(
            parse_legacy(Path::new("bad.vtk"), text.as_bytes()).is_err(),
            "{text:?}"
        );
    }
}
