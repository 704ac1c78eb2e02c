//! VTK files: legacy `.vtk` and XML `.vtu` (in [`vtu`]), both hand-written.
//!
//! The legacy reader is hand-written because `vtkio` 0.6.3 cannot read the legacy
//! 5.1 layout (`OFFSETS`/`CONNECTIVITY`) that VTK 9 and ParaView 5.10+ write, and
//! pre-allocates from untrusted counts. It accepts versions 2.0 to 5.1, ASCII or
//! (big endian) BINARY, `UNSTRUCTURED_GRID` or `POLYDATA`: triangles are kept,
//! polygons, quads and pixels fan-triangulated, triangle strips split, other cells
//! dropped. Every 1-component `SCALARS` or `FIELD` array of `POINT_DATA` (any numeric
//! type) becomes a point array; cell data and other attributes are skipped.
//!
//! The legacy writer produces ASCII `UNSTRUCTURED_GRID` (version 3.0, readable by
//! ParaView and VTK), `double` points and one `SCALARS <name> double 1` per point
//! array (names with blanks or `%` are %-encoded as VTK does).

mod vtu;

pub(crate) use vtu::{read_vtu, write_vtu};

use super::off::{capacity, check_triangles, clip, create, finish, vertex_index, Lexer, Real};
use super::{PointArray, SurfaceData};
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Reads the legacy VTK file `path`.
pub(crate) fn read_legacy(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_legacy(path, &bytes)
}

/// Cells as offsets into a connectivity list.
#[derive(Default)]
struct Cells {
    offsets: Vec<usize>,
    conn: Vec<u64>,
}

impl Cells {
    fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
    fn cell(&self, i: usize) -> &[u64] {
        &self.conn[self.offsets[i]..self.offsets[i + 1]]
    }
}

struct Legacy<'a> {
    lx: Lexer<'a>,
    binary: bool,
    version: f64,
}

impl<'a> Legacy<'a> {
    fn keyword(&mut self, what: &str) -> Result<String> {
        Ok(self.lx.word(what)?.to_ascii_uppercase())
    }

    /// Reads `count` values of VTK type `ty`, passing each to `f`.
    fn values(&mut self, ty: &str, count: usize, mut f: impl FnMut(f64)) -> Result<()> {
        if !self.binary {
            for _ in 0..count {
                f(self.lx.real("a data value")?);
            }
            return Ok(());
        }
        let size = match ty.to_ascii_lowercase().as_str() {
            "unsigned_char" | "char" => 1,
            "unsigned_short" | "short" => 2,
            "unsigned_int" | "int" | "float" => 4,
            "unsigned_long" | "long" | "double" | "vtktypeint64" | "vtktypeuint64"
            | "vtkidtype" => 8,
            t => {
                return Err(self
                    .lx
                    .err(format!("unsupported binary data type '{}'", clip(t))))
            }
        };
        self.lx.rest_of_line();
        let bytes = count
            .checked_mul(size)
            .and_then(|n| self.lx.take_bytes(n))
            .ok_or_else(|| {
                self.lx
                    .err(format!("truncated binary data ({count} values)"))
            })?;
        let ty = ty.to_ascii_lowercase();
        for c in bytes.chunks_exact(size) {
            let mut b = [0u8; 8];
            b[..size].copy_from_slice(c);
            f(match ty.as_str() {
                "unsigned_char" => f64::from(c[0]),
                "char" => f64::from(c[0] as i8),
                "unsigned_short" => f64::from(u16::from_be_bytes([b[0], b[1]])),
                "short" => f64::from(i16::from_be_bytes([b[0], b[1]])),
                "unsigned_int" => f64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]])),
                "int" => f64::from(i32::from_be_bytes([b[0], b[1], b[2], b[3]])),
                "float" => f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
                "double" => f64::from_be_bytes(b),
                "unsigned_long" | "vtktypeuint64" => u64::from_be_bytes(b) as f64,
                _ => i64::from_be_bytes(b) as f64,
            });
        }
        Ok(())
    }

    /// Reads `count` non-negative integers of type `ty`.
    fn indices(&mut self, ty: &str, count: usize, out: &mut Vec<u64>) -> Result<()> {
        out.reserve(capacity(count, self.lx.remaining(), 1));
        let mut bad = None;
        self.values(ty, count, |v| {
            if v >= 0.0 && v.fract() == 0.0 && v < 1.8e19 {
                out.push(v as u64);
            } else {
                bad.get_or_insert(v);
                out.push(0);
            }
        })?;
        match bad {
            Some(v) => Err(self.lx.err(format!("bad index or count {v}"))),
            None => Ok(()),
        }
    }

    /// Reads a `CELLS`/`POLYGONS`/... block after its keyword.
    fn cells(&mut self) -> Result<Cells> {
        let n = self.lx.count("a cell count")?;
        let size = self.lx.count("a cell list size")?;
        let mut cells = Cells::default();
        if self.version >= 5.0 {
            let mut offsets = Vec::new();
            for (key, count, out) in [
                ("OFFSETS", n, &mut offsets),
                ("CONNECTIVITY", size, &mut cells.conn),
            ] {
                if self.keyword(key)? != key {
                    return Err(self.lx.err(format!("expected {key}")));
                }
                let ty = self.lx.word("a data type")?.to_string();
                self.indices(&ty, count, out)?;
            }
            if offsets.first().is_some_and(|&o| o != 0)
                || offsets.windows(2).any(|w| w[0] > w[1])
                || offsets.last().is_some_and(|&o| o as usize != size)
            {
                return Err(self.lx.err("bad cell OFFSETS"));
            }
            cells.offsets = offsets.into_iter().map(|o| o as usize).collect();
        } else {
            let mut list = Vec::new();
            self.indices("int", size, &mut list)?;
            cells
                .offsets
                .reserve(capacity(n.saturating_add(1), size, 1));
            cells.offsets.push(0);
            let mut it = list.into_iter();
            for _ in 0..n {
                let k = it
                    .next()
                    .ok_or_else(|| self.lx.err("cell list too short"))?;
                let before = cells.conn.len();
                cells.conn.extend(it.by_ref().take(k as usize));
                if cells.conn.len() - before != k as usize {
                    return Err(self.lx.err("cell list too short"));
                }
                cells.offsets.push(cells.conn.len());
            }
            if it.next().is_some() {
                return Err(self.lx.err("cell list longer than announced"));
            }
        }
        Ok(cells)
    }

    /// Reads an optional `LOOKUP_TABLE name` line after `SCALARS`.
    fn skip_lookup_name(&mut self) -> Result<()> {
        let save = self.lx.clone();
        match self.lx.token() {
            Some(t) if t.eq_ignore_ascii_case(b"LOOKUP_TABLE") => {
                self.lx.word("a lookup table name")?;
            }
            _ => self.lx = save,
        }
        Ok(())
    }

    /// Skips a `METADATA` block (up to an empty line), if one comes next.
    fn skip_metadata(&mut self) {
        let save = self.lx.clone();
        if self
            .lx
            .token()
            .is_some_and(|t| t.eq_ignore_ascii_case(b"METADATA"))
        {
            self.lx.rest_of_line();
            while self.lx.remaining() > 0 && !self.lx.rest_of_line().trim_ascii().is_empty() {}
        } else {
            self.lx = save;
        }
    }
}

/// Decodes VTK's %XX escapes in array names.
fn decode_name(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok());
        match hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
            Some(c) if b[i] == b'%' => {
                out.push(c);
                i += 3;
            }
            _ => {
                out.push(b[i]);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Appends the triangles of one cell of VTK type `ty` to `out`.
fn triangulate(ty: u64, c: &[u64], out: &mut Vec<[u64; 3]>) {
    match ty {
        5 | 22 if c.len() >= 3 => out.push([c[0], c[1], c[2]]),
        7 | 9 => (2..c.len()).for_each(|j| out.push([c[0], c[j - 1], c[j]])),
        8 if c.len() == 4 => {
            out.push([c[0], c[1], c[3]]);
            out.push([c[0], c[3], c[2]]);
        }
        6 => (2..c.len()).for_each(|j| {
            out.push(if j % 2 == 0 {
                [c[j - 2], c[j - 1], c[j]]
            } else {
                [c[j - 1], c[j - 2], c[j]]
            })
        }),
        _ => {}
    }
}

fn parse_legacy(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut lx = Lexer::new(path, bytes, false);
    let head = String::from_utf8_lossy(lx.rest_of_line()).to_ascii_lowercase();
    let version = head
        .strip_prefix('#')
        .map(str::trim_start)
        .and_then(|h| h.strip_prefix("vtk datafile version"))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .ok_or_else(|| Error::parse(path, "line 1: not a legacy VTK file"))?;
    lx.rest_of_line();
    let mut r = Legacy {
        lx,
        binary: false,
        version,
    };
    r.binary = match r.keyword("ASCII or BINARY")?.as_str() {
        "ASCII" => false,
        "BINARY" => true,
        s => {
            return Err(r
                .lx
                .err(format!("expected ASCII or BINARY, found '{}'", clip(s))))
        }
    };
    if r.keyword("DATASET")? != "DATASET" {
        return Err(r.lx.err("expected DATASET"));
    }
    let kind = r.keyword("a dataset type")?;
    if kind != "UNSTRUCTURED_GRID" && kind != "POLYDATA" {
        return Err(r.lx.err(format!("unsupported dataset '{}'", clip(&kind))));
    }
    let mut data = SurfaceData::default();
    let mut tris: Vec<[u64; 3]> = Vec::new();
    let mut grid_cells: Option<Cells> = None;
    let mut in_points = false;
    let mut count = 0;
    while let Some(tok) = r.lx.token() {
        let key = String::from_utf8_lossy(tok).to_ascii_uppercase();
        match key.as_str() {
            "POINTS" => {
                let n = r.lx.count("the point count")?;
                let ty = r.lx.word("a data type")?.to_string();
                let mut flat =
                    Vec::with_capacity(capacity(3 * n.min(usize::MAX / 3), r.lx.remaining(), 1));
                r.values(&ty, n.saturating_mul(3), |v| flat.push(v))?;
                data.vertices = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                r.skip_metadata();
            }
            "CELLS" => grid_cells = Some(r.cells()?),
            "CELL_TYPES" => {
                let n = r.lx.count("the cell count")?;
                let cells = grid_cells
                    .take()
                    .ok_or_else(|| r.lx.err("CELL_TYPES before CELLS"))?;
                if n != cells.len() {
                    return Err(r
                        .lx
                        .err(format!("{n} cell types for {} cells", cells.len())));
                }
                let mut types = Vec::new();
                r.indices("int", n, &mut types)?;
                for (i, &t) in types.iter().enumerate() {
                    triangulate(t, cells.cell(i), &mut tris);
                }
            }
            "POLYGONS" | "TRIANGLE_STRIPS" | "LINES" | "VERTICES" => {
                let cells = r.cells()?;
                let ty = if key == "POLYGONS" {
                    7
                } else if key == "LINES" {
                    0
                } else {
                    6
                };
                let ty = if key == "VERTICES" { 0 } else { ty };
                (0..cells.len()).for_each(|i| triangulate(ty, cells.cell(i), &mut tris));
            }
            "POINT_DATA" | "CELL_DATA" => {
                let n = r.lx.count("the data count")?;
                in_points = key == "POINT_DATA";
                count = n;
                if in_points && n != data.vertices.len() {
                    return Err(r
                        .lx
                        .err(format!("POINT_DATA {n} for {} points", data.vertices.len())));
                }
            }
            "SCALARS" => {
                let name = decode_name(r.lx.word("a name")?);
                let ty = r.lx.word("a data type")?.to_string();
                let save = r.lx.clone();
                let ncomp = match r.lx.token().map(|t| {
                    std::str::from_utf8(t)
                        .ok()
                        .and_then(|s| s.parse::<usize>().ok())
                }) {
                    Some(Some(k)) if (1..=4).contains(&k) => k,
                    _ => {
                        r.lx = save;
                        1
                    }
                };
                r.skip_lookup_name()?;
                attribute(&mut r, &mut data, in_points, name, &ty, ncomp, count)?;
            }
            "VECTORS" | "NORMALS" | "TENSORS" | "TENSORS6" => {
                r.lx.word("a name")?;
                let ty = r.lx.word("a data type")?.to_string();
                let k = match key.as_str() {
                    "TENSORS" => 9,
                    "TENSORS6" => 6,
                    _ => 3,
                };
                attribute(&mut r, &mut data, false, String::new(), &ty, k, count)?;
            }
            "TEXTURE_COORDINATES" => {
                r.lx.word("a name")?;
                let k = r.lx.count("a dimension")?.min(3);
                let ty = r.lx.word("a data type")?.to_string();
                attribute(&mut r, &mut data, false, String::new(), &ty, k, count)?;
            }
            "COLOR_SCALARS" => {
                r.lx.word("a name")?;
                let k = r.lx.count("a component count")?.min(4);
                attribute(
                    &mut r,
                    &mut data,
                    false,
                    String::new(),
                    "unsigned_char",
                    k,
                    count,
                )?;
            }
            "LOOKUP_TABLE" => {
                r.lx.word("a name")?;
                let n = r.lx.count("a table size")?;
                r.values("unsigned_char", n.saturating_mul(4), |_| {})?;
            }
            "FIELD" => {
                r.lx.word("a name")?;
                let arrays = r.lx.count("an array count")?;
                for _ in 0..arrays {
                    let name = decode_name(r.lx.word("an array name")?);
                    if name == "NULL_ARRAY" {
                        continue;
                    }
                    let k = r.lx.count("a component count")?;
                    let tuples = r.lx.count("a tuple count")?;
                    let ty = r.lx.word("a data type")?.to_string();
                    let keep = in_points && k == 1 && tuples == data.vertices.len();
                    attribute(&mut r, &mut data, keep, name, &ty, k, tuples)?;
                }
            }
            "METADATA" => {
                r.lx.rest_of_line();
                while r.lx.remaining() > 0 && !r.lx.rest_of_line().trim_ascii().is_empty() {}
            }
            k => return Err(r.lx.err(format!("unknown keyword '{}'", clip(k)))),
        }
    }
    if grid_cells.is_some() {
        return Err(Error::parse(path, "CELLS without CELL_TYPES"));
    }
    let n = data.vertices.len();
    data.triangles.reserve(tris.len());
    for t in tris {
        let tri = t.map(|i| vertex_index(i, n));
        match tri {
            [Some(a), Some(b), Some(c)] => data.triangles.push([a, b, c]),
            _ => {
                return Err(Error::parse(
                    path,
                    format!("cell vertex index out of range (0..{n}) in {t:?}"),
                ))
            }
        }
    }
    Ok(data)
}

/// Reads one attribute of `ncomp` components for each of `count` points or cells,
/// kept as a point array when `keep` and it has one component.
fn attribute(
    r: &mut Legacy<'_>,
    data: &mut SurfaceData,
    keep: bool,
    name: String,
    ty: &str,
    ncomp: usize,
    count: usize,
) -> Result<()> {
    if keep && ncomp == 1 {
        let mut values = Vec::with_capacity(capacity(count, r.lx.remaining(), 1));
        r.values(ty, count, |v| values.push(v))?;
        data.point_data.retain(|a| a.name != name);
        data.point_data.push(PointArray { name, values });
    } else {
        r.values(ty, count.saturating_mul(ncomp), |_| {})?;
    }
    r.skip_metadata();
    Ok(())
}

/// Encodes an array name the way VTK does (blanks, `%` and non-ASCII as %XX).
fn encode_name(s: &str) -> String {
    let mut out = String::new();
    for b in s.bytes() {
        if b.is_ascii_graphic() && b != b'%' {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    if out.is_empty() {
        out.push_str("array");
    }
    out
}

/// Writes `data` as an ASCII legacy `UNSTRUCTURED_GRID` with double points.
pub(crate) fn write_legacy(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    let (n, m) = (data.vertices.len(), data.triangles.len());
    write!(w, "# vtk DataFile Version 3.0\nabgs surface\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {n} double\n").map_err(io)?;
    for p in &data.vertices {
        writeln!(w, "{} {} {}", Real(p[0]), Real(p[1]), Real(p[2])).map_err(io)?;
    }
    writeln!(w, "CELLS {m} {}", 4 * m).map_err(io)?;
    for t in &data.triangles {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2]).map_err(io)?;
    }
    writeln!(w, "CELL_TYPES {m}").map_err(io)?;
    for _ in 0..m {
        writeln!(w, "5").map_err(io)?;
    }
    if !data.point_data.is_empty() {
        writeln!(w, "POINT_DATA {n}").map_err(io)?;
    }
    for a in &data.point_data {
        writeln!(
            w,
            "SCALARS {} double 1\nLOOKUP_TABLE default",
            encode_name(&a.name)
        )
        .map_err(io)?;
        for v in &a.values {
            writeln!(w, "{}", Real(*v)).map_err(io)?;
        }
    }
    finish(path, w)
}

#[cfg(test)]
pub(super) mod tests;
