//! `.abgs`: a whole grid in one binary buffer — to save it and load it back
//! quickly, or to send it from one process to others (MPI: serialise on one
//! rank, broadcast the bytes, deserialise on every rank).
//!
//! It keeps what a text format loses or makes a reader redo: coordinates,
//! sizes and arrays bit for bit, the input report's history (welded,
//! dropped, flipped counts), and the layout of the BVH (tree shape and
//! triangle order, the costly part of building it; the boxes are recomputed
//! from the coordinates, never read). Loading checks everything as
//! [`Grid::from_arrays`] does and rebuilds only the adjacency (see
//! [`Grid::from_parts`]); a stored BVH layout is checked in full
//! ([`crate::spatial::BvhLayout`]) and would otherwise be rebuilt. The
//! loaded grid answers every query bit for bit as the saved one.
//!
//! # Format, version 1
//!
//! Every number is little-endian; no padding; offsets in bytes.
//!
//! | offset | type | field |
//! |---|---|---|
//! | 0 | `[u8; 8]` | magic `89 41 42 47 53 0D 0A 1A` (`\x89ABGS\r\n\x1a`: a non-ASCII first byte, CR LF and Ctrl-Z, as PNG's, so that a text-mode copy or a 7-bit channel shows) |
//! | 8 | `u32` | format version, 1 ([`VERSION`]) |
//! | 12 | `u32` | byte-order marker `0x0A0B0C0D`, so the bytes `0D 0C 0B 0A`; `0A 0B 0C 0D` is a big-endian writer's, refused by name |
//! | 16 | `u32` | flags: bit 0 the grid has sizes, bit 1 a BVH layout is stored; other bits 0 |
//! | 20 | `u32` | `A`, the number of named per-vertex arrays besides the sizes |
//! | 24 | `u64` | `V`, vertices (1 to 2³² − 1) |
//! | 32 | `u64` | `T`, triangles (1 to 2³² − 1) |
//! | 40 | `u64` | `N`, BVH nodes: 0 without a layout, else 1 to 2T − 1 |
//! | 48 | `u64` | length of the whole buffer, checksum included |
//! | 56 | `u64` | reserved, 0 |
//! | 64 | 8 × `u64` | input history: input vertices, input triangles, welded vertices, triangles dropped for a repeated corner, for zero area, triangles flipped, non-orientable bodies, reserved (0) |
//! | 128 | `V` × 3 `f64` | vertex coordinates x y z |
//! | … | `T` × 3 `u32` | triangles, 0-based vertex indices |
//! | … | `V` × `f64` | sizes (flag bit 0 only) |
//! | … | `A` × (`u32` L, L bytes, `V` × `f64`) | named arrays: name length, UTF-8 name, values |
//! | … | `N` × 2 `u32` | BVH nodes (flag bit 1 only), root first, depth-first: leaf `[first slot, count > 0]`, inner `[right child, 0]` (left child next) |
//! | … | `T` × `u32` | BVH primitive slots: the triangle in each (flag bit 1 only) |
//! | end − 4 | `u32` | CRC-32 (IEEE 802.3, as zlib and PNG) of every byte before it |
//!
//! # Checks on reading, in order
//!
//! Length at least 68; magic; byte-order marker; version; the stated length
//! equals the buffer's; checksum; flags and reserved fields; counts, whose
//! sections must add up to the length exactly *before* anything is allocated
//! (a count cannot make the reader allocate more than the buffer's size);
//! UTF-8 names; then [`Grid::from_parts`]: coordinates finite, indices in
//! range, sizes finite and > 0, no degenerate triangle, the history agreeing
//! with the counts, the BVH layout a valid tree over the triangles.
//! Errors: [`Error::Parse`] for a corrupt, truncated or inconsistent buffer,
//! [`Error::UnsupportedFormat`] for another version or byte order, and the
//! errors of [`Grid::from_arrays`] for bad content. Never a panic.

use crate::error::{Error, Result};
use crate::io::PointArray;
use crate::mesh::{Grid, GridParts, InputHistory};
use crate::spatial::BvhLayout;
use std::path::Path;

/// The first 8 bytes of every `.abgs` buffer.
pub const MAGIC: [u8; 8] = *b"\x89ABGS\r\n\x1a";
/// The format version this library writes and reads.
pub const VERSION: u32 = 1;
/// The byte-order marker, written little-endian.
const BYTE_ORDER: u32 = 0x0A0B_0C0D;
const HEADER_LEN: usize = 64;
const HISTORY_LEN: usize = 64;
const CHECKSUM_LEN: usize = 4;
/// The smallest buffer: a header and a checksum.
pub const MIN_LEN: usize = HEADER_LEN + CHECKSUM_LEN;
const FLAG_SIZES: u32 = 1;
const FLAG_BVH: u32 = 2;

/// Bytes of the encoding of `grid` (with its BVH layout when `with_bvh`). O(A).
pub fn encoded_len(grid: &Grid, with_bvh: bool) -> usize {
    let (nv, nt) = (grid.vertices().len(), grid.triangles().len());
    let sizes = if grid.sizes().is_some() { 8 * nv } else { 0 };
    let arrays: usize = grid
        .point_arrays()
        .iter()
        .map(|a| 4 + a.name.len() + 8 * nv)
        .sum();
    let bvh = if with_bvh {
        8 * grid.bvh().nodes.len() + 4 * nt
    } else {
        0
    };
    HEADER_LEN + HISTORY_LEN + 24 * nv + 12 * nt + sizes + arrays + bvh + CHECKSUM_LEN
}

/// The encoding of `grid`, BVH layout included. O(V + F).
pub fn encode(grid: &Grid) -> Vec<u8> {
    encode_with(grid, true)
}

/// The encoding of `grid`, with its BVH layout when `with_bvh` (without, a
/// reader builds the BVH: smaller, slower to load). O(V + F).
pub fn encode_with(grid: &Grid, with_bvh: bool) -> Vec<u8> {
    let mut out = vec![0u8; encoded_len(grid, with_bvh)];
    let n = Writer::new(&mut out).grid(grid, with_bvh);
    debug_assert_eq!(n, out.len());
    out
}

/// Writes the encoding of `grid` (BVH layout included) into the start of
/// `out` and returns its length, [`encoded_len`]`(grid, true)`. When `out` is
/// shorter, nothing is written and the error says how long it must be.
/// O(V + F).
pub fn encode_into(grid: &Grid, out: &mut [u8]) -> Result<usize> {
    let n = encoded_len(grid, true);
    let Some(dst) = out.get_mut(..n) else {
        return Err(Error::InvalidArgument(format!(
            "the buffer holds {} bytes, the grid needs {n}",
            out.len()
        )));
    };
    Ok(Writer::new(dst).grid(grid, true))
}

/// The grid encoded in `bytes`, checked in full (module documentation).
/// O(V + F log F) (the adjacency is rebuilt; the BVH too when not stored).
pub fn decode(bytes: &[u8]) -> Result<Grid> {
    decode_named(bytes, "abgs buffer")
}

/// [`decode`], with `name` (a file, say) in the messages.
fn decode_named(bytes: &[u8], name: &str) -> Result<Grid> {
    Grid::from_parts(parse(bytes, name)?)
}

/// Reads an `.abgs` file. A file that does not start with [`MAGIC`] is
/// refused after its first bytes (a large file of another kind is not read).
pub fn read(path: &Path) -> Result<Grid> {
    use std::io::Read;
    let name = path.display().to_string();
    let io = |e| Error::io(path, e);
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut head = Vec::with_capacity(MIN_LEN);
    (&mut file)
        .take(MIN_LEN as u64)
        .read_to_end(&mut head)
        .map_err(io)?;
    if !head.starts_with(&MAGIC) {
        return Err(parse(&head, &name).err().unwrap_or_else(|| Error::Parse {
            path: name.clone(),
            msg: "not an abgs grid".into(),
        }));
    }
    file.read_to_end(&mut head).map_err(io)?;
    decode_named(&head, &name)
}

/// Writes `grid` to an `.abgs` file (BVH layout included).
pub fn write(path: &Path, grid: &Grid) -> Result<()> {
    std::fs::write(path, encode(grid)).map_err(|e| Error::io(path, e))
}

/// Checks the framing of `bytes` (length, magic, byte order, version,
/// checksum, counts) and splits it into a grid's parts, not yet checked as a
/// grid. O(size of `bytes`).
pub fn parse(bytes: &[u8], name: &str) -> Result<GridParts> {
    let corrupt = |msg: String| Error::Parse {
        path: name.to_string(),
        msg,
    };
    let len = bytes.len();
    if len < MIN_LEN {
        let what = if bytes.starts_with(&MAGIC[..len.min(8)]) {
            "truncated"
        } else {
            "not an abgs grid"
        };
        return Err(corrupt(format!(
            "{what}: {len} bytes, an abgs grid has at least {MIN_LEN}"
        )));
    }
    let mut h = Reader::new(&bytes[..HEADER_LEN], name);
    let magic = h.take(8)?;
    if magic != MAGIC {
        return Err(corrupt(format!(
            "not an abgs grid: it starts with {magic:02X?}, an abgs grid with {MAGIC:02X?}"
        )));
    }
    let version = h.u32()?;
    let order = h.u32()?;
    if order == BYTE_ORDER.swap_bytes() {
        return Err(Error::UnsupportedFormat(format!(
            "{name}: written in big-endian byte order (marker 0A 0B 0C 0D); \
             abgs grids are little-endian"
        )));
    }
    if order != BYTE_ORDER {
        return Err(corrupt(format!(
            "byte-order marker {:02X?} is neither little- nor big-endian (corrupt)",
            order.to_le_bytes()
        )));
    }
    if version != VERSION {
        return Err(Error::UnsupportedFormat(format!(
            "{name}: abgs format version {version}; this library reads version {VERSION}"
        )));
    }
    let flags = h.u32()?;
    let n_arrays = h.u32()?;
    let (nv, nt, n_nodes, stated, reserved) = (h.u64()?, h.u64()?, h.u64()?, h.u64()?, h.u64()?);
    if stated != len as u64 {
        return Err(corrupt(if stated > len as u64 {
            format!("truncated: the header says {stated} bytes, {len} given")
        } else {
            format!("{} bytes after the end of the grid", len as u64 - stated)
        }));
    }
    let (body, sum) = bytes.split_at(len - CHECKSUM_LEN);
    let stored = u32::from_le_bytes([sum[0], sum[1], sum[2], sum[3]]);
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(corrupt(format!(
            "checksum mismatch (stored {stored:08x}, computed {computed:08x}): the buffer is corrupt"
        )));
    }
    if flags & !(FLAG_SIZES | FLAG_BVH) != 0 || reserved != 0 {
        return Err(corrupt(format!(
            "unknown flags {flags:#x} or reserved field {reserved} set"
        )));
    }
    let (has_sizes, has_bvh) = (flags & FLAG_SIZES != 0, flags & FLAG_BVH != 0);
    if nv > u32::MAX as u64 || nt > u32::MAX as u64 || has_bvh != (n_nodes > 0) {
        return Err(corrupt(format!(
            "counts out of range: {nv} vertices, {nt} triangles, {n_nodes} BVH nodes \
             (flags {flags:#x})"
        )));
    }
    // Everything but the named arrays, in u128 (no overflow); then the arrays
    // must fit what is left, each taking at least 4 + 8V bytes.
    let (v, t, n) = (nv as u128, nt as u128, n_nodes as u128);
    let fixed = (HEADER_LEN + HISTORY_LEN + CHECKSUM_LEN) as u128
        + 24 * v
        + 12 * t
        + if has_sizes { 8 * v } else { 0 }
        + if has_bvh { 8 * n + 4 * t } else { 0 };
    let per_array = 4 + 8 * v;
    if fixed + n_arrays as u128 * per_array > len as u128 {
        return Err(corrupt(format!(
            "{nv} vertices, {nt} triangles, {n_arrays} arrays and {n_nodes} BVH nodes \
             do not fit in {len} bytes"
        )));
    }
    let (nv, nt, n_nodes) = (nv as usize, nt as usize, n_nodes as usize);
    let mut r = Reader::new(&body[HEADER_LEN..], name);
    let hist = r.u64s(8)?;
    if hist[7] != 0 {
        return Err(corrupt("reserved history field set".into()));
    }
    let history = InputHistory {
        input_vertices: hist[0],
        input_triangles: hist[1],
        welded_vertices: hist[2],
        dropped_repeated_index: hist[3],
        dropped_zero_area: hist[4],
        flipped_triangles: hist[5],
        non_orientable_bodies: hist[6],
    };
    let vertices = r.f64s(3 * nv)?;
    let vertices = vertices
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let triangles = r.u32s(3 * nt)?;
    let triangles = triangles
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let sizes = if has_sizes { Some(r.f64s(nv)?) } else { None };
    let mut arrays = Vec::new();
    for i in 0..n_arrays {
        let l = r.u32()? as usize;
        let name = std::str::from_utf8(r.take(l)?)
            .map_err(|_| corrupt(format!("the name of array {i} is not UTF-8")))?
            .to_string();
        arrays.push(PointArray {
            name,
            values: r.f64s(nv)?,
        });
    }
    let bvh = if has_bvh {
        let nodes = r.u32s(2 * n_nodes)?;
        Some(BvhLayout {
            nodes: nodes.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
            prim_triangle: r.u32s(nt)?,
        })
    } else {
        None
    };
    if r.remaining() != 0 {
        return Err(corrupt(format!(
            "{} bytes left over between the sections and the checksum",
            r.remaining()
        )));
    }
    Ok(GridParts {
        vertices,
        triangles,
        sizes,
        arrays,
        history,
        bvh,
    })
}

/// Bounds-checked little-endian reads from a byte slice.
struct Reader<'a> {
    rest: &'a [u8],
    /// The buffer's name in messages.
    name: &'a str,
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8], name: &'a str) -> Self {
        Reader { rest: bytes, name }
    }

    fn remaining(&self) -> usize {
        self.rest.len()
    }

    /// The next `n` bytes (an error past the end: the counts were checked
    /// against the length, so this is a second guard, never expected).
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.rest.len() {
            return Err(Error::Parse {
                path: self.name.into(),
                msg: format!(
                    "a section runs past the end ({n} bytes wanted, {} left)",
                    self.rest.len()
                ),
            });
        }
        let (a, b) = self.rest.split_at(n);
        self.rest = b;
        Ok(a)
    }

    fn u32(&mut self) -> Result<u32> {
        Ok(self.u32s(1)?[0])
    }

    fn u64(&mut self) -> Result<u64> {
        Ok(self.u64s(1)?[0])
    }

    fn u32s(&mut self, n: usize) -> Result<Vec<u32>> {
        let (c, _) = self.take(4 * n)?.as_chunks::<4>();
        Ok(c.iter().map(|b| u32::from_le_bytes(*b)).collect())
    }

    fn u64s(&mut self, n: usize) -> Result<Vec<u64>> {
        let (c, _) = self.take(8 * n)?.as_chunks::<8>();
        Ok(c.iter().map(|b| u64::from_le_bytes(*b)).collect())
    }

    fn f64s(&mut self, n: usize) -> Result<Vec<f64>> {
        let (c, _) = self.take(8 * n)?.as_chunks::<8>();
        Ok(c.iter().map(|b| f64::from_le_bytes(*b)).collect())
    }
}

/// Little-endian writes into a slice sized by [`encoded_len`].
struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl<'a> Writer<'a> {
    fn new(out: &'a mut [u8]) -> Self {
        Writer { out, at: 0 }
    }

    fn put(&mut self, b: &[u8]) {
        self.out[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
    }

    fn u32s(&mut self, v: impl IntoIterator<Item = u32>) {
        for x in v {
            self.put(&x.to_le_bytes());
        }
    }

    fn u64s(&mut self, v: impl IntoIterator<Item = u64>) {
        for x in v {
            self.put(&x.to_le_bytes());
        }
    }

    fn f64s(&mut self, v: &[f64]) {
        for x in v {
            self.put(&x.to_le_bytes());
        }
    }

    /// Writes the whole encoding (`out` is exactly [`encoded_len`] long) and
    /// returns its length.
    fn grid(mut self, g: &Grid, with_bvh: bool) -> usize {
        let (nv, nt) = (g.vertices().len(), g.triangles().len());
        let bvh = g.bvh();
        let n_nodes = if with_bvh { bvh.nodes.len() } else { 0 };
        let flags =
            if g.sizes().is_some() { FLAG_SIZES } else { 0 } | if with_bvh { FLAG_BVH } else { 0 };
        let total = self.out.len();
        self.put(&MAGIC);
        self.u32s([VERSION, BYTE_ORDER, flags, g.point_arrays().len() as u32]);
        self.u64s([nv as u64, nt as u64, n_nodes as u64, total as u64, 0]);
        let h = InputHistory::of(g.report());
        self.u64s([
            h.input_vertices,
            h.input_triangles,
            h.welded_vertices,
            h.dropped_repeated_index,
            h.dropped_zero_area,
            h.flipped_triangles,
            h.non_orientable_bodies,
            0,
        ]);
        self.f64s(g.vertices().as_flattened());
        self.u32s(g.triangles().as_flattened().iter().copied());
        if let Some(s) = g.sizes() {
            self.f64s(s);
        }
        for a in g.point_arrays() {
            self.u32s([a.name.len() as u32]);
            self.put(a.name.as_bytes());
            self.f64s(&a.values);
        }
        if with_bvh {
            self.u32s(bvh.nodes.iter().flat_map(|n| [n.start, n.count]));
            self.u32s(bvh.prim_triangle.iter().copied());
        }
        let crc = crc32fast::hash(&self.out[..self.at]);
        self.put(&crc.to_le_bytes());
        self.at
    }
}
