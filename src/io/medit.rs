//! Medit ASCII mesh (`.mesh`) with an optional solution file (`.sol`) beside it.
//!
//! Reading takes `Vertices`, `Triangles` and `Quadrilaterals` (split in two
//! triangles); every other section (`Edges`, `Corners`, `Ridges`, `Normals`,
//! `Tetrahedra`, ...) is skipped up to the next keyword. Keywords are matched
//! case-insensitively; `#` starts a comment. `Dimension 2` meshes get z = 0. If
//! `stem.sol` exists, its first scalar `SolAtVertices` field becomes the point array
//! `size` (a `.sol` holding no scalar field, e.g. an anisotropic metric, is ignored).
//!
//! Writing produces `MeshVersionFormatted 2`, `Dimension 3`, `Vertices` (ref 0) and
//! `Triangles` (ref 0); when a point array named `size` exists, `stem.sol` is written
//! too, with one scalar field (`SolAtVertices`, type `1 1`) as MMG's `-met` reads it.
//! Without `size`, an existing `.sol` beside the target is left untouched.

use super::off::{capacity, check_triangles, create, finish, vertex_index, Lexer, Real};
use super::{PointArray, SurfaceData};
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Reads `path` (a `.mesh`) and the `.sol` beside it, if any.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let mut data = parse_mesh(path, &bytes)?;
    let sol = path.with_extension("sol");
    if sol.is_file() {
        let bytes = std::fs::read(&sol).map_err(|e| Error::io(&sol, e))?;
        if let Some(values) = parse_sol(&sol, &bytes, data.vertices.len())? {
            data.point_data.push(PointArray {
                name: "size".into(),
                values,
            });
        }
    }
    Ok(data)
}

/// Whether a token starts a keyword (section name) rather than a number.
fn is_keyword(tok: &[u8]) -> bool {
    tok.first().is_some_and(|c| c.is_ascii_alphabetic())
        && !tok.eq_ignore_ascii_case(b"nan")
        && !tok.eq_ignore_ascii_case(b"inf")
        && !tok.eq_ignore_ascii_case(b"infinity")
}

/// Skips numeric tokens up to the next keyword, which it returns.
fn skip_section<'a>(lx: &mut Lexer<'a>) -> Option<&'a [u8]> {
    loop {
        let t = lx.token()?;
        if is_keyword(t) {
            return Some(t);
        }
    }
}

fn parse_mesh(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut lx = Lexer::new(path, bytes, true);
    let mut dim = 3usize;
    let mut data = SurfaceData::default();
    let mut faces: Vec<([u64; 4], usize)> = Vec::new();
    let mut seen_vertices = false;
    let mut next = lx.token();
    while let Some(tok) = next {
        let key = String::from_utf8_lossy(tok).to_ascii_lowercase();
        next = match key.as_str() {
            "meshversionformatted" => {
                let v = lx.count("the mesh version")?;
                if !(1..=4).contains(&v) {
                    return Err(lx.err(format!("unsupported MeshVersionFormatted {v}")));
                }
                lx.token()
            }
            "dimension" => {
                dim = lx.count("the dimension")?;
                if dim != 2 && dim != 3 {
                    return Err(lx.err(format!("unsupported dimension {dim}")));
                }
                lx.token()
            }
            "vertices" => {
                if seen_vertices {
                    return Err(lx.err("a second Vertices section"));
                }
                seen_vertices = true;
                let n = lx.count("the vertex count")?;
                data.vertices = Vec::with_capacity(capacity(n, lx.remaining(), 8));
                for _ in 0..n {
                    let mut p = [0.0; 3];
                    for c in p.iter_mut().take(dim) {
                        *c = lx.real("a vertex coordinate")?;
                    }
                    lx.parse::<i64>("a vertex reference")?;
                    data.vertices.push(p);
                }
                lx.token()
            }
            "triangles" | "quadrilaterals" => {
                let k = if key == "triangles" { 3 } else { 4 };
                let n = lx.count("the element count")?;
                faces.reserve(capacity(n, lx.remaining(), 2 * k + 2));
                for _ in 0..n {
                    let mut f = [u64::MAX; 4];
                    for v in f.iter_mut().take(k) {
                        *v = lx.parse::<u64>("a vertex index")?;
                    }
                    lx.parse::<i64>("an element reference")?;
                    faces.push((f, lx.token_line()));
                }
                lx.token()
            }
            "end" => break,
            _ => {
                let is_counted = lx.token();
                match is_counted {
                    Some(t) if is_keyword(t) => Some(t),
                    Some(_) => skip_section(&mut lx),
                    None => None,
                }
            }
        };
    }
    let n = data.vertices.len();
    for (f, line) in faces {
        let mut t = [0u32; 4];
        for (dst, &i) in t.iter_mut().zip(&f) {
            if i == u64::MAX {
                break;
            }
            *dst = i
                .checked_sub(1)
                .and_then(|i| vertex_index(i, n))
                .ok_or_else(|| {
                    Error::parse(
                        path,
                        format!("line {line}: vertex index {i} out of range (1..={n})"),
                    )
                })?;
        }
        data.triangles.push([t[0], t[1], t[2]]);
        if f[3] != u64::MAX {
            data.triangles.push([t[0], t[2], t[3]]);
        }
    }
    Ok(data)
}

/// The first scalar field of the `SolAtVertices` section, `None` when it has none.
fn parse_sol(path: &Path, bytes: &[u8], nv: usize) -> Result<Option<Vec<f64>>> {
    let mut lx = Lexer::new(path, bytes, true);
    let mut dim = 3usize;
    let mut next = lx.token();
    while let Some(tok) = next {
        let key = String::from_utf8_lossy(tok).to_ascii_lowercase();
        next = match key.as_str() {
            "dimension" => {
                dim = lx.count("the dimension")?;
                if dim != 2 && dim != 3 {
                    return Err(lx.err(format!("unsupported dimension {dim}")));
                }
                lx.token()
            }
            "solatvertices" => {
                let n = lx.count("the solution count")?;
                if n != nv {
                    return Err(lx.err(format!("{n} solutions for {nv} mesh vertices")));
                }
                let nfields = lx.count("the number of solution fields")?;
                let mut widths = Vec::with_capacity(nfields.min(64));
                for _ in 0..nfields {
                    widths.push(match lx.count("a solution type")? {
                        1 => 1,
                        2 => dim,
                        3 => dim * (dim + 1) / 2,
                        t => return Err(lx.err(format!("unknown solution type {t}"))),
                    });
                }
                let Some(first) = widths.iter().position(|&w| w == 1) else {
                    return Ok(None);
                };
                let skip_before: usize = widths[..first].iter().sum();
                let skip_after: usize = widths[first + 1..].iter().sum();
                let mut values = Vec::with_capacity(capacity(n, lx.remaining(), 2));
                for _ in 0..n {
                    for _ in 0..skip_before {
                        lx.real("a solution value")?;
                    }
                    values.push(lx.real("a solution value")?);
                    for _ in 0..skip_after {
                        lx.real("a solution value")?;
                    }
                }
                return Ok(Some(values));
            }
            "end" => break,
            _ => skip_section(&mut lx),
        };
    }
    Err(Error::parse(path, "no SolAtVertices section"))
}

/// Writes `data` to `path` (`.mesh`) and, when it has a `size` array, `stem.sol`.
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    write!(
        w,
        "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n{}\n",
        data.vertices.len()
    )
    .map_err(io)?;
    for p in &data.vertices {
        writeln!(w, "{} {} {} 0", Real(p[0]), Real(p[1]), Real(p[2])).map_err(io)?;
    }
    write!(w, "\nTriangles\n{}\n", data.triangles.len()).map_err(io)?;
    for t in &data.triangles {
        writeln!(w, "{} {} {} 0", t[0] + 1, t[1] + 1, t[2] + 1).map_err(io)?;
    }
    writeln!(w, "\nEnd").map_err(io)?;
    finish(path, w)?;
    if let Some(size) = data.point_array("size") {
        let sol = path.with_extension("sol");
        let mut w = create(&sol)?;
        let io = |e| Error::io(&sol, e);
        write!(
            w,
            "MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n{}\n1 1\n\n",
            size.len()
        )
        .map_err(io)?;
        for v in size {
            writeln!(w, "{}", Real(*v)).map_err(io)?;
        }
        writeln!(w, "\nEnd").map_err(io)?;
        finish(&sol, w)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::off::tests::{same_bits, sample, TempPath};

    #[test]
    fn round_trip_with_sol() {
        let t = TempPath::new("rt.mesh");
        let _sol = TempPath(t.0.with_extension("sol"));
        let d = sample();
        write(&t.0, &d).unwrap();
        assert!(t.0.with_extension("sol").is_file());
        let r = read(&t.0).unwrap();
        assert!(same_bits(&r.vertices, &d.vertices));
        assert_eq!(r.triangles, d.triangles);
        assert_eq!(r.point_data.len(), 1);
        let (a, b) = (&r.point_data[0].values, &d.point_data[0].values);
        assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }

    #[test]
    fn round_trip_without_sol() {
        let t = TempPath::new("nosol.mesh");
        let mut d = sample();
        d.point_data.clear();
        write(&t.0, &d).unwrap();
        assert!(!t.0.with_extension("sol").exists());
        assert_eq!(read(&t.0).unwrap(), d);
    }

    #[test]
    fn skips_unknown_sections() {
        let text = "# made by hand\nMeshVersionFormatted 1\nDimension\n3\nVertices\n4\n0 0 0 1\n\
                    1 0 0 1\n1 1 0 1\n0 1 0 1\nEdges\n2\n1 2 0\n2 3 0\nCorners 1 1\n\
                    Ridges\n1\n1\nQuadrilaterals\n1\n1 2 3 4 7\nTriangles\n1\n1 2 3 0\n\
                    Normals\n1\n0 0 1\nNormalAtVertices\n1\n1 1\nEnd\n";
        let d = parse_mesh(Path::new("x.mesh"), text.as_bytes()).unwrap();
        assert_eq!(d.vertices.len(), 4);
        assert_eq!(d.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
        let d2 = parse_mesh(
            Path::new("x.mesh"),
            b"Dimension 2\nVertices 3\n0 0 0\n1 0 0\n0 1 0\nTriangles 1\n1 2 3 0\nEnd\n",
        )
        .unwrap();
        assert_eq!(d2.vertices[1], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn sol_with_several_fields() {
        let text = "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n3 2 1 3\n\
                    1 2 3 0.5 1 0 0 1 0 1\n4 5 6 0.25 1 0 0 1 0 1\nEnd\n";
        let v = parse_sol(Path::new("x.sol"), text.as_bytes(), 2).unwrap();
        assert_eq!(v, Some(vec![0.5, 0.25]));
        let aniso = "Dimension 3\nSolAtVertices\n1\n1 3\n1 0 0 1 0 1\nEnd\n";
        assert_eq!(
            parse_sol(Path::new("x.sol"), aniso.as_bytes(), 1).unwrap(),
            None
        );
    }

    #[test]
    fn malformed() {
        let p = Path::new("bad.mesh");
        for text in [
            "Vertices\n3\n0 0 0 0\n1 0 0 0\n",
            "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 4 0\n",
            "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n0 1 2 0\n",
            "Vertices\n3\n0 0 0 0\n1 0 x 0\n0 1 0 0\n",
            "Vertices\n99999999999999999\n0 0 0 0\n",
            "Dimension 7\n",
            "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n2\n1 2 3 0\n",
        ] {
            assert!(parse_mesh(p, text.as_bytes()).is_err(), "{text:?}");
        }
        let e = parse_mesh(
            p,
            b"Vertices 3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles 1\n1 2 9 0\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("line 6"), "{e}");
        let s = Path::new("bad.sol");
        assert!(parse_sol(s, b"SolAtVertices\n3\n1 1\n1\n2\n", 3).is_err());
        assert!(parse_sol(s, b"SolAtVertices\n2\n1 1\n1\n2\n", 3).is_err());
        assert!(parse_sol(s, b"SolAtVertices\n1\n1 9\n1\n", 1).is_err());
        assert!(parse_sol(s, b"garbage", 1).is_err());
    }
}
