//! Object File Format (`.off`), ASCII, and the small text helpers shared by the
//! hand-written text readers and writers of this module tree ([`Lexer`], [`Real`],
//! [`check_triangles`], [`capacity`]).
//!
//! Reading accepts `OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF` and the like: only the
//! first three columns of a vertex line are read, the rest of the line (normals,
//! colours, texture coordinates) is ignored, and so are face colours after the
//! vertex indices. Polygons are fan-triangulated; faces of fewer than three vertices
//! are skipped. `#` starts a comment. Binary OFF and `4OFF`/`nOFF` are rejected.

use super::{PointArray, SurfaceData};
use crate::error::{Error, Result};
use std::fmt;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::str::FromStr;

/// A float written so that it parses back to the same bits: shortest round-trip
/// digits, plain notation for moderate magnitudes, exponent notation otherwise.
pub(super) struct Real(pub(super) f64);

impl fmt::Display for Real {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// An initial capacity for `count` items announced by a file of which `remaining`
/// bytes are left, each item taking at least `min_bytes`: never trusts the count
/// beyond what the file can hold.
pub(super) fn capacity(count: usize, remaining: usize, min_bytes: usize) -> usize {
    count.min(remaining / min_bytes.max(1) + 1)
}

/// Fails with [`Error::OutOfRange`] when a triangle of `data` names a missing vertex
/// (writers check this before writing anything).
pub(super) fn check_triangles(data: &SurfaceData) -> Result<()> {
    let n = data.vertices.len();
    for (t, tri) in data.triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
            return Err(Error::OutOfRange(format!(
                "triangle {t} refers to vertex {v}, but there are {n} vertices"
            )));
        }
    }
    Ok(())
}

/// Converts a parsed vertex index to `u32`, checking it against `n` vertices.
pub(super) fn vertex_index(i: u64, n: usize) -> Option<u32> {
    usize::try_from(i)
        .ok()
        .filter(|&i| i < n)
        .and_then(|i| u32::try_from(i).ok())
}

/// Creates `path` for buffered writing.
pub(super) fn create(path: &Path) -> Result<BufWriter<File>> {
    File::create(path)
        .map(BufWriter::new)
        .map_err(|e| Error::io(path, e))
}

/// Flushes a buffered writer, mapping the error to [`Error::Io`].
pub(super) fn finish(path: &Path, mut w: BufWriter<File>) -> Result<()> {
    w.flush().map_err(|e| Error::io(path, e))
}

/// Whitespace-separated tokens of an in-memory text file, with line numbers for
/// error messages (cloning one saves a position to come back to).
#[derive(Clone)]
pub(super) struct Lexer<'a> {
    path: &'a Path,
    data: &'a [u8],
    pos: usize,
    line: usize,
    tok_line: usize,
    comments: bool,
}

impl<'a> Lexer<'a> {
    /// A lexer over `data` (the content of `path`); with `comments`, a token starting
    /// with `#` starts a comment running to the end of its line.
    pub(super) fn new(path: &'a Path, data: &'a [u8], comments: bool) -> Self {
        Lexer {
            path,
            data,
            pos: 0,
            line: 1,
            tok_line: 1,
            comments,
        }
    }

    fn skip_ws(&mut self) {
        while let Some(&c) = self.data.get(self.pos) {
            if c == b'\n' {
                self.line += 1;
                self.pos += 1;
            } else if c.is_ascii_whitespace() {
                self.pos += 1;
            } else if c == b'#' && self.comments {
                while self.data.get(self.pos).is_some_and(|&c| c != b'\n') {
                    self.pos += 1;
                }
            } else {
                break;
            }
        }
    }

    /// The next token, `None` at the end of the file.
    pub(super) fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        self.tok_line = self.line;
        let start = self.pos;
        while self
            .data
            .get(self.pos)
            .is_some_and(|c| !c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        (self.pos > start).then(|| &self.data[start..self.pos])
    }

    /// The next token as text; an error at the end of the file.
    pub(super) fn word(&mut self, what: &str) -> Result<&'a str> {
        match self.token() {
            None => Err(self.err(format!("unexpected end of file, expected {what}"))),
            Some(t) => std::str::from_utf8(t)
                .map_err(|_| self.err(format!("expected {what}, found non-UTF-8 text"))),
        }
    }

    /// The next token parsed as a `T` (`what` names it in the error message).
    pub(super) fn parse<T: FromStr>(&mut self, what: &str) -> Result<T> {
        let w = self.word(what)?;
        w.parse()
            .map_err(|_| self.err(format!("expected {what}, found '{}'", clip(w))))
    }

    /// The next token as an `f64`.
    pub(super) fn real(&mut self, what: &str) -> Result<f64> {
        self.parse::<f64>(what)
    }

    /// The next token as a count or index.
    pub(super) fn count(&mut self, what: &str) -> Result<usize> {
        self.parse::<usize>(what)
    }

    /// The rest of the current line (without its end of line), which is consumed.
    pub(super) fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while self.data.get(self.pos).is_some_and(|&c| c != b'\n') {
            self.pos += 1;
        }
        let end = self.pos;
        if self.pos < self.data.len() {
            self.pos += 1;
            self.line += 1;
        }
        &self.data[start..end]
    }

    /// The next `n` raw bytes (binary payloads), `None` when fewer are left.
    pub(super) fn take_bytes(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len())?;
        let bytes = &self.data[self.pos..end];
        self.pos = end;
        Some(bytes)
    }

    /// The line of the last token read.
    pub(super) fn token_line(&self) -> usize {
        self.tok_line
    }

    /// Bytes not yet consumed (to cap allocations made from announced counts).
    pub(super) fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    /// A parse error located at the line of the last token.
    pub(super) fn err(&self, msg: impl fmt::Display) -> Error {
        Error::parse(self.path, format!("line {}: {msg}", self.tok_line))
    }
}

/// At most 40 characters of `s`, for error messages.
pub(super) fn clip(s: &str) -> String {
    if s.chars().count() > 40 {
        s.chars().take(40).collect::<String>() + "..."
    } else {
        s.to_string()
    }
}

/// Reads the OFF file `path`.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(path, &bytes)
}

fn parse(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut lx = Lexer::new(path, bytes, true);
    let head = lx.word("the OFF header")?;
    let Some(prefix) = head.strip_suffix("OFF") else {
        return Err(lx.err(format!("expected an OFF header, found '{}'", clip(head))));
    };
    if prefix.contains('4') || prefix.contains('n') {
        return Err(lx.err(format!("'{head}' (not 3-D) files are not supported")));
    }
    if !prefix.chars().all(|c| matches!(c, 'C' | 'N' | 'S' | 'T')) {
        return Err(lx.err(format!("unknown OFF variant '{}'", clip(head))));
    }
    let first = lx.word("the vertex count")?;
    if first == "BINARY" {
        return Err(lx.err("binary OFF is not supported"));
    }
    let nv: usize = first.parse().map_err(|_| {
        lx.err(format!(
            "expected the vertex count, found '{}'",
            clip(first)
        ))
    })?;
    let nf = lx.count("the face count")?;
    let _edges = lx.count("the edge count")?;
    lx.rest_of_line();
    let mut vertices = Vec::with_capacity(capacity(nv, lx.remaining(), 6));
    for _ in 0..nv {
        let x = lx.real("a vertex coordinate")?;
        let y = lx.real("a vertex coordinate")?;
        let z = lx.real("a vertex coordinate")?;
        vertices.push([x, y, z]);
        lx.rest_of_line();
    }
    let mut triangles = Vec::with_capacity(capacity(nf, lx.remaining(), 8));
    let mut poly = Vec::new();
    for _ in 0..nf {
        let k = lx.count("a face vertex count")?;
        poly.clear();
        for _ in 0..k {
            let i = lx.parse::<u64>("a vertex index")?;
            let v = vertex_index(i, nv)
                .ok_or_else(|| lx.err(format!("vertex index {i} out of range (0..{nv})")))?;
            poly.push(v);
        }
        for j in 2..poly.len() {
            triangles.push([poly[0], poly[j - 1], poly[j]]);
        }
        lx.rest_of_line();
    }
    Ok(SurfaceData {
        vertices,
        triangles,
        point_data: Vec::<PointArray>::new(),
    })
}

/// Writes `data` as ASCII OFF (point arrays are dropped).
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    writeln!(w, "OFF").map_err(io)?;
    writeln!(w, "{} {} 0", data.vertices.len(), data.triangles.len()).map_err(io)?;
    for p in &data.vertices {
        writeln!(w, "{} {} {}", Real(p[0]), Real(p[1]), Real(p[2])).map_err(io)?;
    }
    for t in &data.triangles {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2]).map_err(io)?;
    }
    finish(path, w)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A unique temporary path ending in `name`, removed on drop.
    pub(crate) struct TempPath(pub(crate) std::path::PathBuf);

    impl TempPath {
        /// A fresh path in the temporary directory whose name ends in `name`.
        pub(crate) fn new(name: &str) -> Self {
            use std::sync::atomic::{AtomicUsize, Ordering};
            static N: AtomicUsize = AtomicUsize::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            let dir = std::env::temp_dir();
            TempPath(dir.join(format!("abgs_io_{}_{n}_{name}", std::process::id())))
        }
    }

    impl Drop for TempPath {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    /// A small surface with awkward coordinates and a `size` array.
    pub(crate) fn sample() -> SurfaceData {
        SurfaceData {
            vertices: vec![
                [0.1, -2.5e-300, 1.0 / 3.0],
                [1e20, 0.0, -0.0],
                [std::f64::consts::PI, 7.0, 1e-7],
                [-1.5, 2.0f64.sqrt(), 123456.789],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]],
            point_data: vec![PointArray {
                name: "size".into(),
                values: vec![0.1, 0.2, 1.0 / 7.0, 5e-9],
            }],
        }
    }

    /// Bitwise comparison of vertex coordinates.
    pub(crate) fn same_bits(a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()))
    }

    /// A model of the shared test-mesh folder (`../shared/meshes` beside the
    /// checkout); a test that needs it fails when it is missing.
    pub(crate) fn shared_mesh(name: &str) -> std::path::PathBuf {
        let p = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes/")).join(name);
        assert!(
            p.is_file(),
            "{} is missing: the tests need ../shared beside the checkout",
            p.display()
        );
        p
    }

    #[test]
    fn real_round_trips() {
        for x in [
            0.1,
            1e-300,
            -1e300,
            1.0 / 3.0,
            1e16,
            9.99e15,
            1e-5,
            5e-324,
            -0.0,
        ] {
            let s = Real(x).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
    }

    #[test]
    fn round_trip() {
        let t = TempPath::new("rt.off");
        let mut d = sample();
        write(&t.0, &d).unwrap();
        let r = read(&t.0).unwrap();
        assert!(same_bits(&r.vertices, &d.vertices));
        assert_eq!(r.triangles, d.triangles);
        d.point_data.clear();
        assert_eq!(r.point_data, d.point_data);
    }

    #[test]
    fn variants_comments_polygons() {
        let text = "# c\nCOFF\n# another\n5 2 0\n0 0 0 255 0 0 255\n1 0 0 1 1 1 1\n1 1 0 1 1 1 1\n0 1 0 1 1 1 1\n2 2 2 0 0 0 0\n4 0 1 2 3 255 0 0\n2 0 4\n";
        let d = parse(Path::new("x.off"), text.as_bytes()).unwrap();
        assert_eq!(d.vertices.len(), 5);
        assert_eq!(d.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let text = "NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
        let d = parse(Path::new("x.off"), text.as_bytes()).unwrap();
        assert_eq!(d.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn malformed() {
        let p = Path::new("bad.off");
        for text in [
            "",
            "PLY\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            "OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n",
            "OFF\n18446744073709551615 1 0\n0 0 0\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n99999999999 0 1 2\n",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
            "4OFF\n1 0 0\n0 0 0 0\n",
            "OFF BINARY\n",
        ] {
            assert!(parse(p, text.as_bytes()).is_err(), "{text:?}");
        }
        let e = parse(p, b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap_err();
        assert!(e.to_string().contains("line 6"), "{e}");
    }

    #[test]
    fn write_rejects_bad_index() {
        let t = TempPath::new("bad.off");
        let mut d = sample();
        d.triangles.push([0, 1, 9]);
        assert!(matches!(write(&t.0, &d), Err(Error::OutOfRange(_))));
    }

    #[test]
    fn shared_fandisk() {
        let p = shared_mesh("cgal_fandisk.off");
        let d = read(&p).unwrap();
        assert_eq!((d.vertices.len(), d.triangles.len()), (6475, 12946));
        let n = d.vertices.len() as u32;
        assert!(d.triangles.iter().flatten().all(|&v| v < n));
    }
}
