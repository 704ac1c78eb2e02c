//! STL (`.stl`), ASCII or binary, through the `stl_io` crate.
//!
//! Reading returns a triangle soup: three new vertices per facet, in file order
//! (welding is the grid builder's job); f32 coordinates are widened to f64. A file
//! whose size matches the binary layout exactly is read as binary even when its
//! header starts with `solid` (as many CAD exporters write); ASCII files may hold
//! several `solid ... endsolid` blocks, and a bare `solid` line (no name) is
//! accepted. Writing produces binary STL with f32 coordinates (so it is lossy), face
//! normals computed in f64.

use super::off::{check_triangles, create, finish};
use super::SurfaceData;
use crate::error::{Error, Result};
use std::fs::OpenOptions;
use std::io::{Cursor, Write};
use std::path::Path;
use stl_io::{Normal, Triangle, Vertex};

/// Reads the STL file `path` as a triangle soup.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(path, bytes)
}

fn parse(path: &Path, mut bytes: Vec<u8>) -> Result<SurfaceData> {
    let mut out = SurfaceData::default();
    if is_binary(&bytes) {
        // stl_io probes for ASCII by a leading "solid ": blank the (ignored) header.
        bytes[..80].fill(b' ');
        read_chunk(path, &bytes, &mut out)?;
        return Ok(out);
    }
    let start = bytes
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    if !bytes[start..].starts_with(b"solid") {
        if bytes.len() < 84 {
            return Err(Error::parse(
                path,
                "neither ASCII STL (no 'solid') nor binary STL (shorter than 84 bytes)",
            ));
        }
        // Binary with a count that does not match the size: stl_io reports truncation.
        read_chunk(path, &bytes, &mut out)?;
        return Ok(out);
    }
    for (i, solid) in solids(&bytes[start..]).into_iter().enumerate() {
        read_chunk(path, &solid, &mut out)
            .map_err(|e| Error::parse(path, format!("in solid {}: {}", i + 1, parse_msg(e))))?;
    }
    Ok(out)
}

/// Whether `bytes` has exactly the size that its binary triangle count announces.
fn is_binary(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    84 + 50 * n == bytes.len() as u64
}

/// Splits ASCII STL text into one chunk per `solid` block, each starting with
/// `"solid "` as stl_io expects.
fn solids(text: &[u8]) -> Vec<Vec<u8>> {
    let mut chunks: Vec<Vec<u8>> = Vec::new();
    for line in text.split_inclusive(|&b| b == b'\n') {
        let trimmed = line.trim_ascii_start();
        let is_start =
            trimmed.starts_with(b"solid") && trimmed.get(5).is_none_or(|c| c.is_ascii_whitespace());
        if is_start {
            let mut chunk = b"solid ".to_vec();
            chunk.extend_from_slice(trimmed[5..].trim_ascii_start());
            if !chunk.ends_with(b"\n") {
                chunk.push(b'\n');
            }
            chunks.push(chunk);
        } else if let Some(c) = chunks.last_mut() {
            c.extend_from_slice(line);
        }
    }
    chunks
}

fn parse_msg(e: Error) -> String {
    match e {
        Error::Parse { msg, .. } => msg,
        e => e.to_string(),
    }
}

/// Appends the facets of one stl_io stream to `out`.
fn read_chunk(path: &Path, bytes: &[u8], out: &mut SurfaceData) -> Result<()> {
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| Error::parse(path, format!("invalid STL: {e}")))?;
    let hint = reader.size_hint().0.min(bytes.len() / 50 + 1);
    out.vertices.reserve(3 * hint);
    out.triangles.reserve(hint);
    for (k, t) in reader.enumerate() {
        let t = t.map_err(|e| Error::parse(path, format!("facet {}: {e}", k + 1)))?;
        let base = u32::try_from(out.vertices.len())
            .ok()
            .filter(|b| *b <= u32::MAX - 3)
            .ok_or_else(|| Error::parse(path, "too many facets"))?;
        for v in t.vertices {
            out.vertices.push(v.0.map(f64::from));
        }
        out.triangles.push([base, base + 1, base + 2]);
    }
    Ok(())
}

/// Writes `data` as binary STL (f32; point arrays are dropped).
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    if u32::try_from(data.triangles.len()).is_err() {
        return Err(Error::InvalidArgument(
            "binary STL holds at most 2^32-1 triangles".into(),
        ));
    }
    let facets = data.triangles.iter().map(|t| {
        let [a, b, c] = t.map(|i| data.vertices[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 0.0 && len.is_finite() {
            n.map(|x| (x / len) as f32)
        } else {
            [0.0; 3]
        };
        Triangle {
            normal: Normal::new(n),
            vertices: [a, b, c].map(|p| Vertex::new(p.map(|x| x as f32))),
        }
    });
    let mut w = create(path)?;
    stl_io::write_stl(&mut w, facets).map_err(|e| Error::io(path, e))?;
    finish(path, w)?;
    // stl_io writes an all-zero header, which Gmsh refuses: name the writer instead
    // (never starting with "solid", which would suggest ASCII).
    let mut header = [b' '; 80];
    header[..HEADER.len()].copy_from_slice(HEADER);
    OpenOptions::new()
        .write(true)
        .open(path)
        .and_then(|mut f| f.write_all(&header))
        .map_err(|e| Error::io(path, e))
}

/// The start of the 80-byte header of written binary STL files.
const HEADER: &[u8] = b"binary STL written by abgs";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::off::tests::{sample, shared_mesh, TempPath};

    #[test]
    fn round_trip_binary() {
        let t = TempPath::new("rt.stl");
        let d = sample();
        write(&t.0, &d).unwrap();
        let r = read(&t.0).unwrap();
        assert_eq!(r.triangles.len(), d.triangles.len());
        assert_eq!(r.vertices.len(), 3 * d.triangles.len());
        for (k, t) in d.triangles.iter().enumerate() {
            for (j, &v) in t.iter().enumerate() {
                let want = d.vertices[v as usize].map(|x| x as f32 as f64);
                assert_eq!(r.vertices[3 * k + j], want);
            }
            assert_eq!(
                r.triangles[k],
                [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2]
            );
        }
        assert!(r.point_data.is_empty());
        assert!(std::fs::read(&t.0).unwrap().starts_with(HEADER));
    }

    const ASCII: &str = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
                         vertex 0 1 0.5\nendloop\nendfacet\nendsolid a\n";

    #[test]
    fn ascii_multi_solid_and_bare_solid() {
        let text = format!("{ASCII}solid\n{}", &ASCII[8..]);
        let d = parse(Path::new("a.stl"), text.into_bytes()).unwrap();
        assert_eq!(d.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(d.vertices[5], [0.0, 1.0, 0.5]);
    }

    #[test]
    fn binary_with_solid_header() {
        let t = TempPath::new("solidhdr.stl");
        write(&t.0, &sample()).unwrap();
        let mut bytes = std::fs::read(&t.0).unwrap();
        bytes[..12].copy_from_slice(b"solid binary");
        let d = parse(&t.0, bytes).unwrap();
        assert_eq!(d.triangles.len(), 3);
    }

    #[test]
    fn malformed() {
        let p = Path::new("bad.stl");
        let t = TempPath::new("trunc.stl");
        write(&t.0, &sample()).unwrap();
        let mut truncated = std::fs::read(&t.0).unwrap();
        truncated.truncate(84 + 50 + 20);
        let mut huge = truncated.clone();
        huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        for bytes in [
            Vec::new(),
            b"garbage".to_vec(),
            truncated,
            huge,
            ASCII.replace("vertex 1 0 0", "vertex 1 x 0").into_bytes(),
            ASCII.as_bytes()[..60].to_vec(),
        ] {
            assert!(parse(p, bytes.clone()).is_err(), "{bytes:?}");
        }
    }

    #[test]
    fn shared_hinge() {
        let p = shared_mesh("netgen_hinge.stl");
        let d = read(&p).unwrap();
        assert_eq!(d.triangles.len(), 1212);
        assert_eq!(d.vertices.len(), 3 * d.triangles.len());
    }
}
