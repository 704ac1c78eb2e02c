//! Wavefront OBJ (`.obj`), hand-written.
//!
//! Reading keeps every `v` line as a vertex, in file order (shared vertices stay
//! shared across `o`/`g` groups), in full f64 precision; `f` lines take the position
//! index of each `v`, `v/vt`, `v//vn` or `v/vt/vn` corner (negative indices count
//! back from the last vertex read) and are fan-triangulated. A `v` line with a fourth
//! (`w`) value is divided by it. Everything else (`vt`, `vn`, `l`, `p`, groups,
//! materials) is ignored; `\` continues a line.

use super::off::{check_triangles, clip, create, finish, Real};
use super::SurfaceData;
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Reads the OBJ file `path`.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(path, &bytes)
}

fn parse(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // (index, line) of the largest vertex index met, checked once all `v` are read.
    let mut max_ref: Option<(u64, usize)> = None;
    let mut poly: Vec<u64> = Vec::new();
    let mut nums: Vec<f64> = Vec::with_capacity(4);
    let mut joined = String::new();
    let mut lines = bytes.split(|&b| b == b'\n').enumerate();
    while let Some((ln, raw)) = lines.next() {
        let mut line = String::from_utf8_lossy(raw);
        let mut lineno = ln + 1;
        if line.trim_end().ends_with('\\') {
            joined.clear();
            joined.push_str(&line);
            while joined.trim_end().ends_with('\\') {
                let keep = joined.trim_end().len() - 1;
                joined.truncate(keep);
                joined.push(' ');
                match lines.next() {
                    Some((n, r)) => {
                        joined.push_str(&String::from_utf8_lossy(r));
                        lineno = n + 1;
                    }
                    None => break,
                }
            }
            line = std::borrow::Cow::Borrowed(joined.as_str());
        }
        let err = |msg: String| Error::parse(path, format!("line {lineno}: {msg}"));
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                nums.clear();
                for w in words.by_ref().take(4) {
                    match w.parse::<f64>() {
                        Ok(x) => nums.push(x),
                        Err(_) if nums.len() >= 3 => break,
                        Err(_) => return Err(err(format!("bad vertex coordinate '{}'", clip(w)))),
                    }
                }
                if nums.len() < 3 {
                    return Err(err("a vertex needs three coordinates".into()));
                }
                let mut p = [nums[0], nums[1], nums[2]];
                // Exactly four values: homogeneous w (x y z r g b has six).
                if nums.len() == 4 && words.next().is_none() && nums[3] != 0.0 {
                    p.iter_mut().for_each(|c| *c /= nums[3]);
                }
                vertices.push(p);
            }
            Some("f") => {
                poly.clear();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| err(format!("bad face vertex '{}'", clip(w))))?;
                    let n = vertices.len() as i64;
                    let abs = if i > 0 {
                        i - 1
                    } else if i < 0 && i >= -n {
                        n + i
                    } else {
                        return Err(err(format!(
                            "face vertex index {i} out of range ({n} vertices so far)"
                        )));
                    };
                    let abs = abs as u64;
                    if max_ref.is_none_or(|(m, _)| abs > m) {
                        max_ref = Some((abs, lineno));
                    }
                    poly.push(abs);
                }
                if poly.len() < 3 {
                    return Err(err("a face needs at least three vertices".into()));
                }
                for j in 2..poly.len() {
                    // Indices are range-checked below, once every vertex is known.
                    let t = [poly[0], poly[j - 1], poly[j]];
                    triangles.push(t.map(|v| v.min(u32::MAX as u64) as u32));
                }
            }
            _ => {}
        }
    }
    if let Some((m, lineno)) = max_ref {
        if m >= vertices.len() as u64 || m >= u32::MAX as u64 {
            return Err(Error::parse(
                path,
                format!(
                    "line {lineno}: face vertex index {} out of range (the file has {} vertices)",
                    m + 1,
                    vertices.len()
                ),
            ));
        }
    }
    Ok(SurfaceData {
        vertices,
        triangles,
        point_data: Vec::new(),
    })
}

/// Writes `data` as OBJ (`v` and 1-based `f` lines; point arrays are dropped).
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    writeln!(w, "# written by abgs").map_err(io)?;
    for p in &data.vertices {
        writeln!(w, "v {} {} {}", Real(p[0]), Real(p[1]), Real(p[2])).map_err(io)?;
    }
    for t in &data.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).map_err(io)?;
    }
    finish(path, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::off::tests::{same_bits, sample, shared_mesh, TempPath};

    #[test]
    fn round_trip() {
        let t = TempPath::new("rt.obj");
        let d = sample();
        write(&t.0, &d).unwrap();
        let r = read(&t.0).unwrap();
        assert!(same_bits(&r.vertices, &d.vertices));
        assert_eq!(r.triangles, d.triangles);
        assert!(r.point_data.is_empty());
    }

    #[test]
    fn corners_groups_negative_and_polygons() {
        let text = "mtllib x.mtl\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0 1 0 0\nvt 0 0\nvn 0 0 1\n\
                    f 1/1/1 2/1/1 3/1/1\ng b\nv 0 1 0\nv 0 0 2 2\nf -5//1 -2//1 \\\n -1//1 4\nl 1 2\n";
        let d = parse(Path::new("x.obj"), text.as_bytes()).unwrap();
        assert_eq!(d.vertices.len(), 5);
        assert_eq!(d.vertices[4], [0.0, 0.0, 1.0]);
        assert_eq!(d.triangles, vec![[0, 1, 2], [0, 3, 4], [0, 4, 3]]);
    }

    #[test]
    fn malformed() {
        let p = Path::new("bad.obj");
        for text in [
            "v 0 0\n",
            "v 0 0 x\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n",
        ] {
            assert!(parse(p, text.as_bytes()).is_err(), "{text:?}");
        }
        let e = parse(p, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n").unwrap_err();
        assert!(e.to_string().contains("line 5"), "{e}");
    }

    #[test]
    fn shared_rocker_arm() {
        let p = shared_mesh("ajc_rocker_arm.obj");
        let d = read(&p).unwrap();
        assert_eq!((d.vertices.len(), d.triangles.len()), (10044, 20088));
        let n = d.vertices.len() as u32;
        assert!(d.triangles.iter().flatten().all(|&v| v < n));
    }
}
