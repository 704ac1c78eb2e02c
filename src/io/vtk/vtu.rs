//! VTK XML unstructured grid (`.vtu`): hand-written reader and writer.
//!
//! The reader is hand-written because `vtkio` 0.6.3 misreads common files: it
//! assumes a UInt64 block header when `header_type` is absent (VTK's default is
//! UInt32, as in files written by meshio) and rejects `types` arrays that are not
//! UInt8 (meshio writes Int64). It reads `UnstructuredGrid` and `PolyData` files,
//! every inline piece, with `ascii`, `binary` (base64) or `appended` (raw or base64)
//! data of any numeric type, either byte order, UInt32 or UInt64 headers; compressed
//! files are rejected with a parse error. Triangles are kept, polygons, quads and
//! pixels fan-triangulated, triangle strips split, other cells dropped; every
//! 1-component point array becomes a point array (an array missing from some piece
//! is NaN there).
//!
//! The writer produces one ASCII piece with Float64 points, triangle cells and
//! one Float64 point array per point array (written by hand: `vtkio` 0.6 depends
//! on crates that future Rust versions will reject).

use super::super::off::{capacity, check_triangles, clip, create, finish, vertex_index};
use super::super::{PointArray, SurfaceData};
use super::triangulate;
use crate::error::{Error, Result};
use std::borrow::Cow;
use std::path::Path;

#[derive(Clone, Copy, PartialEq)]
enum Section {
    Other,
    Points,
    Cells,
    Polys,
    Strips,
    PointData,
}

struct ArrayInfo {
    section: Section,
    name: String,
    ty: String,
    ncomp: usize,
    format: String,
    offset: usize,
    text: (usize, usize),
}

#[derive(Default)]
struct PieceInfo {
    points: usize,
    cells: usize,
    polys: usize,
    strips: usize,
    arrays: Vec<ArrayInfo>,
}

struct Ctx<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    little: bool,
    header: usize,
    appended: Option<(usize, bool)>,
}

fn find(bytes: &[u8], from: usize, pat: &[u8]) -> Option<usize> {
    bytes
        .get(from..)?
        .windows(pat.len())
        .position(|w| w == pat)
        .map(|i| i + from)
}

/// Decodes the five predefined XML entities.
fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses the tag starting at `bytes[lt] == b'<'`: (name, attributes, closing,
/// self-closing, position after `>`).
type Tag = (String, Vec<(String, String)>, bool, bool, usize);

fn parse_tag(bytes: &[u8], lt: usize) -> Option<Tag> {
    let mut i = lt + 1;
    let closing = bytes.get(i) == Some(&b'/');
    i += usize::from(closing);
    let start = i;
    while bytes
        .get(i)
        .is_some_and(|c| !c.is_ascii_whitespace() && !b"/>".contains(c))
    {
        i += 1;
    }
    let name = String::from_utf8_lossy(&bytes[start..i]).into_owned();
    let mut attrs = Vec::new();
    loop {
        while bytes.get(i).is_some_and(|c| c.is_ascii_whitespace()) {
            i += 1;
        }
        match *bytes.get(i)? {
            b'>' => return Some((name, attrs, closing, false, i + 1)),
            b'/' if bytes.get(i + 1) == Some(&b'>') => {
                return Some((name, attrs, closing, true, i + 2))
            }
            _ => {}
        }
        let k0 = i;
        while bytes
            .get(i)
            .is_some_and(|&c| c != b'=' && !c.is_ascii_whitespace())
        {
            i += 1;
        }
        let key = String::from_utf8_lossy(&bytes[k0..i]).into_owned();
        while bytes
            .get(i)
            .is_some_and(|&c| c == b'=' || c.is_ascii_whitespace())
        {
            i += 1;
        }
        let q = *bytes.get(i)?;
        if q != b'"' && q != b'\'' {
            return None;
        }
        let v0 = i + 1;
        let v1 = v0 + bytes.get(v0..)?.iter().position(|&c| c == q)?;
        attrs.push((key, unescape(&String::from_utf8_lossy(&bytes[v0..v1]))));
        i = v1 + 1;
    }
}

fn attr<'a>(attrs: &'a [(String, String)], key: &str) -> Option<&'a str> {
    attrs
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

fn count_attr(path: &Path, attrs: &[(String, String)], key: &str) -> Result<usize> {
    attr(attrs, key).map_or(Ok(0), |v| {
        v.trim()
            .parse()
            .map_err(|_| Error::parse(path, format!("bad {key}=\"{}\"", clip(v))))
    })
}

/// Decodes standard base64, ignoring whitespace and stopping at padding.
fn base64(text: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for &c in text {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => break,
            c if c.is_ascii_whitespace() => continue,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    Some(out)
}

fn scalar(ty: &str, c: &[u8], little: bool) -> f64 {
    let mut b = [0u8; 8];
    b[..c.len()].copy_from_slice(c);
    if !little {
        b[..c.len()].reverse();
    }
    let [b0, b1, b2, b3, ..] = b;
    match ty {
        "Int8" => f64::from(b0 as i8),
        "UInt8" => f64::from(b0),
        "Int16" => f64::from(i16::from_le_bytes([b0, b1])),
        "UInt16" => f64::from(u16::from_le_bytes([b0, b1])),
        "Int32" => f64::from(i32::from_le_bytes([b0, b1, b2, b3])),
        "UInt32" => f64::from(u32::from_le_bytes([b0, b1, b2, b3])),
        "Float32" => f64::from(f32::from_le_bytes([b0, b1, b2, b3])),
        "Int64" => i64::from_le_bytes(b) as f64,
        "UInt64" => u64::from_le_bytes(b) as f64,
        _ => f64::from_le_bytes(b),
    }
}

impl Ctx<'_> {
    fn err(&self, a: &ArrayInfo, msg: impl std::fmt::Display) -> Error {
        Error::parse(self.path, format!("DataArray '{}': {msg}", clip(&a.name)))
    }

    /// The values of `a`, which must hold `count` of them.
    fn values(&self, a: &ArrayInfo, count: usize) -> Result<Vec<f64>> {
        let size = match a.ty.as_str() {
            "Int8" | "UInt8" => 1,
            "Int16" | "UInt16" => 2,
            "Int32" | "UInt32" | "Float32" => 4,
            "Int64" | "UInt64" | "Float64" => 8,
            t => return Err(self.err(a, format!("unsupported type '{}'", clip(t)))),
        };
        let text = &self.bytes[a.text.0..a.text.1];
        let raw: Cow<'_, [u8]> = match a.format.as_str() {
            "ascii" => {
                let mut out = Vec::with_capacity(capacity(count, text.len(), 2));
                for tok in text
                    .split(|c| c.is_ascii_whitespace())
                    .filter(|t| !t.is_empty())
                {
                    let s = String::from_utf8_lossy(tok);
                    out.push(
                        s.parse::<f64>()
                            .map_err(|_| self.err(a, format!("bad value '{}'", clip(&s))))?,
                    );
                }
                return self.checked(a, out, count);
            }
            "binary" => Cow::Owned(base64(text).ok_or_else(|| self.err(a, "invalid base64"))?),
            "appended" => {
                let (base, raw) = self
                    .appended
                    .ok_or_else(|| self.err(a, "no AppendedData"))?;
                let start = base.saturating_add(a.offset).min(self.bytes.len());
                let rest = &self.bytes[start..];
                if raw {
                    Cow::Borrowed(rest)
                } else {
                    let head = base64(&rest[..rest.len().min(12)]).unwrap_or_default();
                    let n = self.block_len(&head).unwrap_or(0);
                    let chars = self.header.saturating_add(n).div_ceil(3).saturating_mul(4);
                    let block = &rest[..rest.len().min(chars)];
                    Cow::Owned(base64(block).ok_or_else(|| self.err(a, "invalid base64"))?)
                }
            }
            f => return Err(self.err(a, format!("unsupported format '{}'", clip(f)))),
        };
        let n = self
            .block_len(&raw)
            .ok_or_else(|| self.err(a, "truncated data"))?;
        let data = raw
            .get(self.header..self.header.saturating_add(n))
            .ok_or_else(|| self.err(a, "truncated data"))?;
        let out = data
            .chunks_exact(size)
            .map(|c| scalar(&a.ty, c, self.little))
            .collect();
        self.checked(a, out, count)
    }

    /// The byte count in the block header at the start of `raw`.
    fn block_len(&self, raw: &[u8]) -> Option<usize> {
        let h = raw.get(..self.header)?;
        let v = scalar(
            if self.header == 8 { "UInt64" } else { "UInt32" },
            h,
            self.little,
        );
        Some(v as usize)
    }

    fn checked(&self, a: &ArrayInfo, v: Vec<f64>, count: usize) -> Result<Vec<f64>> {
        if v.len() == count {
            Ok(v)
        } else {
            Err(self.err(a, format!("{} values where {count} are expected", v.len())))
        }
    }

    /// The integer values of `a` (indices, offsets, cell types).
    fn ints(&self, a: &ArrayInfo, count: usize) -> Result<Vec<u64>> {
        self.values(a, count)?
            .into_iter()
            .map(|v| {
                (v >= 0.0 && v.fract() == 0.0 && v < 1.8e19)
                    .then_some(v as u64)
                    .ok_or_else(|| self.err(a, format!("bad index {v}")))
            })
            .collect()
    }

    /// Triangles of the cells in `sec` (`types` gives each cell's VTK type).
    fn cells(&self, p: &PieceInfo, sec: Section, n: usize, out: &mut Vec<[u64; 3]>) -> Result<()> {
        let get = |name: &str| {
            p.arrays
                .iter()
                .find(|a| a.section == sec && a.name == name)
                .ok_or_else(|| Error::parse(self.path, format!("cells without '{name}'")))
        };
        if n == 0 {
            return Ok(());
        }
        let offsets = self.ints(get("offsets")?, n)?;
        let total = *offsets.last().unwrap_or(&0) as usize;
        let conn = self.ints(get("connectivity")?, total)?;
        let types = match sec {
            Section::Cells => self.ints(get("types")?, n)?,
            Section::Strips => vec![6; n],
            _ => vec![7; n],
        };
        let mut start = 0usize;
        for (&end, &ty) in offsets.iter().zip(&types) {
            let cell = conn
                .get(start..end as usize)
                .ok_or_else(|| Error::parse(self.path, "inconsistent cell offsets"))?;
            triangulate(ty, cell, out);
            start = end as usize;
        }
        Ok(())
    }
}

/// Reads the VTK XML file `path`.
pub(crate) fn read_vtu(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_vtu(path, &bytes)
}

fn parse_vtu(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut ctx = Ctx {
        path,
        bytes,
        little: true,
        header: 4,
        appended: None,
    };
    let bad = || Error::parse(path, "malformed XML");
    let mut pieces: Vec<PieceInfo> = Vec::new();
    let mut section = Section::Other;
    let mut kind = None;
    let mut pos = 0;
    while let Some(lt) = find(bytes, pos, b"<") {
        for (open, close) in [(&b"<?"[..], &b"?>"[..]), (b"<!--", b"-->"), (b"<!", b">")] {
            if bytes[lt..].starts_with(open) {
                pos = find(bytes, lt, close).ok_or_else(bad)? + close.len();
                break;
            }
        }
        if pos > lt {
            continue;
        }
        let (name, attrs, closing, empty, after) = parse_tag(bytes, lt).ok_or_else(bad)?;
        pos = after;
        let sec = match name.as_str() {
            "Points" => Section::Points,
            "Cells" => Section::Cells,
            "Polys" => Section::Polys,
            "Strips" => Section::Strips,
            "PointData" => Section::PointData,
            "VTKFile" if !closing => {
                kind = attr(&attrs, "type").map(str::to_string);
                ctx.little = attr(&attrs, "byte_order") != Some("BigEndian");
                ctx.header = if attr(&attrs, "header_type") == Some("UInt64") {
                    8
                } else {
                    4
                };
                if let Some(c) = attr(&attrs, "compressor").filter(|c| !c.is_empty()) {
                    return Err(Error::parse(
                        path,
                        format!(
                            "compressed VTK XML ({}) is not supported: save it uncompressed",
                            clip(c)
                        ),
                    ));
                }
                continue;
            }
            "Piece" if !closing => {
                pieces.push(PieceInfo {
                    points: count_attr(path, &attrs, "NumberOfPoints")?,
                    cells: count_attr(path, &attrs, "NumberOfCells")?,
                    polys: count_attr(path, &attrs, "NumberOfPolys")?,
                    strips: count_attr(path, &attrs, "NumberOfStrips")?,
                    arrays: Vec::new(),
                });
                continue;
            }
            "DataArray" if !closing => {
                let piece = pieces
                    .last_mut()
                    .ok_or_else(|| Error::parse(path, "DataArray outside a Piece"))?;
                let end = if empty {
                    after
                } else {
                    find(bytes, after, b"<").unwrap_or(bytes.len())
                };
                piece.arrays.push(ArrayInfo {
                    section,
                    name: attr(&attrs, "Name").unwrap_or("").to_string(),
                    ty: attr(&attrs, "type").unwrap_or("").to_string(),
                    ncomp: count_attr(path, &attrs, "NumberOfComponents")?.max(1),
                    format: attr(&attrs, "format").unwrap_or("ascii").to_string(),
                    offset: count_attr(path, &attrs, "offset")?,
                    text: (after, end),
                });
                continue;
            }
            "AppendedData" if !closing => {
                let raw = attr(&attrs, "encoding") == Some("raw");
                let us = find(bytes, after, b"_").ok_or_else(bad)?;
                ctx.appended = Some((us + 1, raw));
                break;
            }
            _ => continue,
        };
        if !empty {
            section = if closing { Section::Other } else { sec };
        }
    }
    let polydata = match kind.as_deref() {
        Some("UnstructuredGrid") => false,
        Some("PolyData") => true,
        Some(k) => {
            return Err(Error::parse(
                path,
                format!("unsupported VTK XML type '{}'", clip(k)),
            ))
        }
        None => {
            return Err(Error::parse(
                path,
                "not a VTK XML file (no VTKFile element)",
            ))
        }
    };
    let mut out = SurfaceData::default();
    for p in &pieces {
        let base = out.vertices.len();
        let pts = p
            .arrays
            .iter()
            .find(|a| a.section == Section::Points)
            .ok_or_else(|| Error::parse(path, "a piece has no Points"))?;
        let flat = ctx.values(pts, p.points.saturating_mul(3))?;
        out.vertices
            .extend(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        let mut tris = Vec::new();
        if polydata {
            ctx.cells(p, Section::Polys, p.polys, &mut tris)?;
            ctx.cells(p, Section::Strips, p.strips, &mut tris)?;
        } else {
            ctx.cells(p, Section::Cells, p.cells, &mut tris)?;
        }
        let total = out.vertices.len();
        for t in tris {
            let tri = t.map(|i| {
                i.checked_add(base as u64)
                    .and_then(|i| vertex_index(i, total))
            });
            match tri {
                [Some(a), Some(b), Some(c)] => out.triangles.push([a, b, c]),
                _ => {
                    return Err(Error::parse(
                        path,
                        format!("cell vertex out of range in {t:?}"),
                    ))
                }
            }
        }
        for a in p
            .arrays
            .iter()
            .filter(|a| a.section == Section::PointData && a.ncomp == 1)
        {
            let values = ctx.values(a, p.points)?;
            let k = match out.point_data.iter().position(|x| x.name == a.name) {
                Some(k) => k,
                None => {
                    out.point_data.push(PointArray {
                        name: a.name.clone(),
                        values: vec![f64::NAN; base],
                    });
                    out.point_data.len() - 1
                }
            };
            out.point_data[k].values.truncate(base);
            out.point_data[k].values.extend(values);
        }
        for a in &mut out.point_data {
            a.values.resize(total, f64::NAN);
        }
    }
    Ok(out)
}

/// Escapes a name for an XML attribute value.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// Writes `data` as a VTK XML unstructured grid: one piece, ASCII, Float64 points
/// and point arrays written with Rust's shortest round-trip float format (so a
/// read gives back the same bits), Int64 connectivity and offsets, UInt8 types.
pub(crate) fn write_vtu(path: &Path, data: &SurfaceData) -> Result<()> {
    use std::io::Write;
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e: std::io::Error| Error::io(path, e);
    let (nv, nt) = (data.vertices.len(), data.triangles.len());
    writeln!(w, "<?xml version=\"1.0\"?>").map_err(io)?;
    writeln!(w, "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">").map_err(io)?;
    writeln!(
        w,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{nv}\" NumberOfCells=\"{nt}\">"
    )
    .map_err(io)?;
    if !data.point_data.is_empty() {
        let first = xml_escape(&data.point_data[0].name);
        writeln!(w, "<PointData Scalars=\"{first}\">").map_err(io)?;
        for a in &data.point_data {
            writeln!(w, "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"1\" format=\"ascii\">", xml_escape(&a.name)).map_err(io)?;
            for v in &a.values {
                writeln!(w, "{v:?}").map_err(io)?;
            }
            writeln!(w, "</DataArray>").map_err(io)?;
        }
        writeln!(w, "</PointData>").map_err(io)?;
    }
    writeln!(
        w,
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    )
    .map_err(io)?;
    for p in &data.vertices {
        writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2]).map_err(io)?;
    }
    writeln!(w, "</DataArray>\n</Points>\n<Cells>").map_err(io)?;
    writeln!(
        w,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )
    .map_err(io)?;
    for t in &data.triangles {
        writeln!(w, "{} {} {}", t[0], t[1], t[2]).map_err(io)?;
    }
    writeln!(
        w,
        "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )
    .map_err(io)?;
    for k in 1..=nt {
        writeln!(w, "{}", 3 * k).map_err(io)?;
    }
    writeln!(
        w,
        "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )
    .map_err(io)?;
    for _ in 0..nt {
        writeln!(w, "5").map_err(io)?;
    }
    writeln!(
        w,
        "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
    )
    .map_err(io)?;
    finish(path, w)
}

#[cfg(test)]
mod tests;
