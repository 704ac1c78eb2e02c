//! Tests of the parent module.

use super::*;
use crate::io::off::tests::{same_bits, TempPath};
use crate::io::vtk::tests::{same_arrays, sample2};

#[test]
fn round_trip() {
    let t = TempPath::new("rt.vtu");
    let d = sample2();
    write_vtu(&t.0, &d).unwrap();
    let r = read_vtu(&t.0).unwrap();
    assert!(same_bits(&r.vertices, &d.vertices));
    assert_eq!(r.triangles, d.triangles);
    assert!(
        same_arrays(&r.point_data, &d.point_data),
        "{:?}",
        r.point_data
    );
}

fn b64(data: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = c
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            let ch = if i <= c.len() {
                T[(n >> (18 - 6 * i) & 63) as usize]
            } else {
                b'='
            };
            s.push(ch as char);
        }
    }
    s
}

/// A VTU (or VTP-in-.vtu) file in the given layout, as other writers make them.
fn build(format: &str, h64: bool, big: bool, poly: bool) -> Vec<u8> {
    let conn = [0.0, 1.0, 2.0, 0.0, 1.0, 3.0, 2.0, 0.0, 2.0, 3.0];
    let arrays: Vec<(&str, &str, &str, Vec<f64>)> = vec![
        (
            "PointData",
            "size",
            "Float64",
            vec![0.5, 0.25, 1.0 / 3.0, 2.0],
        ),
        ("PointData", "v", "Float32", vec![0.0; 12]),
        (
            "Points",
            "p",
            "Float32",
            vec![0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.5],
        ),
        ("Cells", "connectivity", "Int64", conn.to_vec()),
        ("Cells", "offsets", "Int32", vec![3.0, 7.0, 10.0]),
        ("Cells", "types", "Int64", vec![5.0, 9.0, 7.0]),
    ];
    let mut body = String::new();
    let mut blob: Vec<u8> = Vec::new();
    let mut text_blob = String::new();
    for (sec, name, ty, vals) in &arrays {
        if poly && *name == "types" {
            continue;
        }
        let mut raw = Vec::new();
        for &v in vals {
            let mut b = match *ty {
                "Float64" => v.to_le_bytes().to_vec(),
                "Float32" => (v as f32).to_le_bytes().to_vec(),
                "Int64" => (v as i64).to_le_bytes().to_vec(),
                _ => (v as i32).to_le_bytes().to_vec(),
            };
            if big {
                b.reverse();
            }
            raw.extend(b);
        }
        let mut head = if h64 {
            (raw.len() as u64).to_le_bytes().to_vec()
        } else {
            (raw.len() as u32).to_le_bytes().to_vec()
        };
        if big {
            head.reverse();
        }
        let block = [head, raw].concat();
        let ncomp = if *sec == "Points" || *name == "v" {
            3
        } else {
            1
        };
        let sec = if poly && *sec == "Cells" {
            "Polys"
        } else {
            sec
        };
        let (fmt, content): (String, String) = match format {
            "ascii" => (
                "ascii".into(),
                vals.iter().map(|v| format!("{v} ")).collect(),
            ),
            "binary" => ("binary".into(), b64(&block)),
            "raw" => {
                let off = blob.len();
                blob.extend(&block);
                (format!("appended\" offset=\"{off}"), String::new())
            }
            _ => {
                let off = text_blob.len();
                text_blob.push_str(&b64(&block));
                (format!("appended\" offset=\"{off}"), String::new())
            }
        };
        body += &format!(
            "<{sec}><DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{ncomp}\" \
             format=\"{fmt}\">\n{content}\n</DataArray></{sec}>\n"
        );
    }
    let (kind, counts) = if poly {
        ("PolyData", "NumberOfPolys=\"3\" NumberOfVerts=\"0\"")
    } else {
        ("UnstructuredGrid", "NumberOfCells=\"3\"")
    };
    let header = if h64 { " header_type=\"UInt64\"" } else { "" };
    let order = if big { "BigEndian" } else { "LittleEndian" };
    let mut out = format!(
        "<?xml version=\"1.0\"?>\n<!-- a <comment> -->\n<VTKFile type=\"{kind}\" version=\"0.1\" \
         byte_order=\"{order}\"{header}>\n<{kind}>\n<Piece NumberOfPoints=\"4\" {counts}>\n\
         {body}</Piece>\n</{kind}>\n"
    )
    .into_bytes();
    match format {
        "raw" => {
            out.extend(b"<AppendedData encoding=\"raw\">\n _");
            out.extend(&blob);
        }
        "base64" => {
            out.extend(b"<AppendedData encoding=\"base64\">\n _");
            out.extend(text_blob.as_bytes());
        }
        _ => {}
    }
    if format == "raw" || format == "base64" {
        out.extend(b"\n</AppendedData>\n");
    }
    out.extend(b"</VTKFile>\n");
    out
}

#[test]
fn all_layouts() {
    let p = Path::new("x.vtu");
    for format in ["ascii", "binary", "raw", "base64"] {
        for (h64, big, poly) in [
            (false, false, false),
            (true, true, false),
            (false, true, true),
        ] {
            let bytes = build(format, h64, big, poly);
            let d =
                parse_vtu(p, &bytes).unwrap_or_else(|e| panic!("{format} {h64} {big} {poly}: {e}"));
            assert_eq!(d.vertices[3], [0.0, 1.0, 0.5]);
            let want = vec![[0, 1, 2], [0, 1, 3], [0, 3, 2], [0, 2, 3]];
            assert_eq!(d.triangles, want, "{format} {h64} {big} {poly}");
            assert_eq!(d.point_data.len(), 1);
            assert_eq!(d.point_array("size").unwrap(), [0.5, 0.25, 1.0 / 3.0, 2.0]);
        }
    }
}

#[test]
fn malformed() {
    let p = Path::new("bad.vtu");
    let good = build("binary", false, false, false);
    let good_s = String::from_utf8(good.clone()).unwrap();
    let raw = build("raw", false, false, false);
    let mut cases: Vec<Vec<u8>> = vec![
        Vec::new(),
        b"garbage".to_vec(),
        b"<VTKFile type=\"ImageData\"></VTKFile>".to_vec(),
        b"<VTKFile type=\"UnstructuredGrid\"><Piece NumberOfPoints=\"1\"></Piece></VTKFile>"
            .to_vec(),
        good[..good.len() / 2].to_vec(),
        raw[..raw.len() - 40].to_vec(),
        good_s
            .replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"99999999999\"")
            .into(),
        good_s
            .replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"x\"")
            .into(),
        good_s
            .replace("version=\"0.1\"", "compressor=\"vtkZLibDataCompressor\"")
            .into(),
        good_s.replace("type=\"Int32\"", "type=\"Bit\"").into(),
        good_s
            .replacen("format=\"binary\">\n", "format=\"binary\">\n!!", 1)
            .into(),
    ];
    let ascii = String::from_utf8(build("ascii", false, false, false)).unwrap();
    cases.push(ascii.replace("3 7 10", "3 7 99").into());
    cases.push(ascii.replace("0 1 2 0 1 3", "0 1 2 0 1 9").into());
    cases.push(ascii.replace("0.5 0.25", "0.5 x").into());
    for c in cases {
        assert!(parse_vtu(p, &c).is_err(), "{}", String::from_utf8_lossy(&c));
    }
}
