//! Gmsh MSH (`.msh`), ASCII, hand-written.
//!
//! (`mshio` 0.4.2 was tried and dropped: it panics on malformed headers, e.g. an
//! over-long data-size field or an odd binary size_t width, it rejects parametric
//! nodes, and it does not read `$NodeData` anyway.)
//!
//! Reading accepts ASCII MSH 4.1 and 2.2 (binary files are rejected with a parse
//! error). Nodes become vertices in file order; triangles are the elements of type 2
//! and, by their three corner nodes, the higher-order triangle types (9, 20-25);
//! other elements and unknown sections are skipped. A node or element tag met again
//! (Gmsh repeats the mesh when a view is saved with it) keeps its first definition.
//! Every scalar (1-component) `$NodeData` view becomes a point array named by its
//! first string tag (a later view of the same name, e.g. a later time step, replaces
//! an earlier one; an unnamed view is called `viewK`); when that leaves exactly one
//! array and it is not called `size`, it is renamed `size`. Nodes a view does not
//! cover get NaN.
//!
//! Writing produces ASCII MSH 4.1: `$MeshFormat`, `$Nodes` (one entity block, dim 2,
//! tag 1, node tags 1..n), `$Elements` (one block of type 2) and one `$NodeData` per
//! point array (string tag = array name, time 0, step 0, 1 component), which Gmsh
//! 4.x merges as a post-processing view usable as a `PostView` background field.

use super::off::{capacity, check_triangles, clip, create, finish, Lexer, Real};
use super::{PointArray, SurfaceData};
use crate::error::{Error, Result};
use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::Path;

/// Reads the ASCII MSH file `path`.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(path, &bytes)
}

/// Node count of a Gmsh element type, for the types met in practice.
fn nodes_of(etype: u32) -> Option<usize> {
    Some(match etype {
        15 => 1,
        1 => 2,
        2 | 8 => 3,
        3 | 4 | 26 => 4,
        7 | 27 => 5,
        6 | 9 | 28 => 6,
        5 | 16 => 8,
        10 | 20 => 9,
        11 | 21 => 10,
        22 => 12,
        19 => 13,
        14 => 14,
        18 | 23 | 24 => 15,
        13 => 18,
        17 | 29 => 20,
        25 => 21,
        12 => 27,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// Whether `etype` is a triangle (of any order) whose first three nodes are corners.
fn is_triangle(etype: u32) -> bool {
    matches!(etype, 2 | 9 | 20..=25)
}

struct View {
    name: String,
    entries: Vec<(u64, f64)>,
    line: usize,
}

#[derive(Default)]
struct Msh {
    v4: bool,
    vertices: Vec<[f64; 3]>,
    tags: HashMap<u64, u32>,
    elems: Vec<([u64; 3], usize)>,
    elem_tags: HashSet<u64>,
    views: Vec<View>,
}

fn parse(path: &Path, bytes: &[u8]) -> Result<SurfaceData> {
    let mut lx = Lexer::new(path, bytes, false);
    let mut m = Msh::default();
    let mut format_seen = false;
    while let Some(tok) = lx.token() {
        let name = String::from_utf8_lossy(tok).into_owned();
        if name != "$MeshFormat" && !format_seen && name.starts_with('$') {
            return Err(lx.err(format!("'{}' before $MeshFormat", clip(&name))));
        }
        match name.as_str() {
            "$MeshFormat" => {
                let version = lx.word("the MSH version")?;
                m.v4 = match version {
                    "4.1" => true,
                    v if v.starts_with("2.") => false,
                    v => {
                        return Err(lx.err(format!(
                            "unsupported MSH version '{}' (expected 4.1 or 2.2)",
                            clip(v)
                        )))
                    }
                };
                if lx.count("the file type")? != 0 {
                    return Err(lx.err("binary MSH is not supported: save it as ASCII"));
                }
                lx.count("the data size")?;
                format_seen = true;
            }
            "$Nodes" if m.v4 => nodes_v4(&mut lx, &mut m)?,
            "$Nodes" => nodes_v2(&mut lx, &mut m)?,
            "$Elements" => elements(&mut lx, &mut m)?,
            "$NodeData" => node_data(&mut lx, &mut m)?,
            s if s.starts_with('$') && !s.starts_with("$End") => {
                let end = format!("$End{}", &s[1..]);
                loop {
                    match lx.token() {
                        Some(t) if t == end.as_bytes() => break,
                        Some(_) => {}
                        None => return Err(lx.err(format!("missing {}", clip(&end)))),
                    }
                }
                continue;
            }
            s => return Err(lx.err(format!("unexpected '{}'", clip(s)))),
        }
        let end = format!("$End{}", &name[1..]);
        let t = lx.word(&end)?;
        if t != end {
            return Err(lx.err(format!("expected {end}, found '{}'", clip(t))));
        }
    }
    if !format_seen {
        return Err(Error::parse(path, "not an MSH file (no $MeshFormat)"));
    }
    finish_mesh(path, m)
}

/// Adds a node; a tag seen before (Gmsh repeats the mesh when a view is saved
/// with it) keeps its first definition.
fn add_node(lx: &Lexer<'_>, m: &mut Msh, tag: u64, p: [f64; 3]) -> Result<()> {
    let idx = u32::try_from(m.vertices.len()).map_err(|_| lx.err("too many nodes"))?;
    if let std::collections::hash_map::Entry::Vacant(e) = m.tags.entry(tag) {
        e.insert(idx);
        m.vertices.push(p);
    }
    Ok(())
}

fn point(lx: &mut Lexer<'_>) -> Result<[f64; 3]> {
    Ok([
        lx.real("a node coordinate")?,
        lx.real("a node coordinate")?,
        lx.real("a node coordinate")?,
    ])
}

fn nodes_v4(lx: &mut Lexer<'_>, m: &mut Msh) -> Result<()> {
    let blocks = lx.count("the number of node blocks")?;
    let total = lx.count("the number of nodes")?;
    lx.parse::<u64>("the minimum node tag")?;
    lx.parse::<u64>("the maximum node tag")?;
    let mut read = 0usize;
    m.vertices.reserve(capacity(total, lx.remaining(), 8));
    let mut tags = Vec::new();
    for _ in 0..blocks {
        let dim = lx.parse::<i32>("the entity dimension")?;
        lx.parse::<i32>("the entity tag")?;
        let extra = match lx.count("the parametric flag")? {
            0 => 0,
            1 => dim.clamp(0, 3) as usize,
            p => return Err(lx.err(format!("bad parametric flag {p}"))),
        };
        let n = lx.count("the number of nodes in the block")?;
        tags.clear();
        tags.reserve(capacity(n, lx.remaining(), 2));
        for _ in 0..n {
            tags.push(lx.parse::<u64>("a node tag")?);
        }
        for &tag in &tags {
            let p = point(lx)?;
            for _ in 0..extra {
                lx.real("a parametric coordinate")?;
            }
            add_node(lx, m, tag, p)?;
        }
        read += n;
    }
    if read != total {
        return Err(lx.err(format!("$Nodes announces {total} nodes but holds {read}")));
    }
    Ok(())
}

fn nodes_v2(lx: &mut Lexer<'_>, m: &mut Msh) -> Result<()> {
    let n = lx.count("the number of nodes")?;
    m.vertices.reserve(capacity(n, lx.remaining(), 8));
    for _ in 0..n {
        let tag = lx.parse::<u64>("a node tag")?;
        let p = point(lx)?;
        add_node(lx, m, tag, p)?;
    }
    Ok(())
}

/// Reads the nodes of element `tag` of type `etype`, keeping triangles (once per
/// element tag, as Gmsh may repeat the mesh in a file).
fn element_nodes(lx: &mut Lexer<'_>, m: &mut Msh, tag: u64, etype: u32) -> Result<()> {
    match nodes_of(etype) {
        Some(k) => {
            let mut t = [0u64; 3];
            for j in 0..k {
                let tag = lx.parse::<u64>("a node tag")?;
                if let Some(slot) = t.get_mut(j) {
                    *slot = tag;
                }
            }
            if is_triangle(etype) && m.elem_tags.insert(tag) {
                m.elems.push((t, lx.token_line()));
            }
        }
        None => {
            lx.rest_of_line();
        }
    }
    Ok(())
}

fn elements(lx: &mut Lexer<'_>, m: &mut Msh) -> Result<()> {
    if m.v4 {
        let blocks = lx.count("the number of element blocks")?;
        lx.count("the number of elements")?;
        lx.parse::<u64>("the minimum element tag")?;
        lx.parse::<u64>("the maximum element tag")?;
        for _ in 0..blocks {
            lx.parse::<i32>("the entity dimension")?;
            lx.parse::<i32>("the entity tag")?;
            let etype = lx.parse::<u32>("the element type")?;
            let n = lx.count("the number of elements in the block")?;
            if nodes_of(etype).is_none() {
                // Unknown type: one element per line.
                lx.rest_of_line();
                for _ in 0..n {
                    if lx.remaining() == 0 {
                        return Err(lx.err("unexpected end of file in $Elements"));
                    }
                    lx.rest_of_line();
                }
                continue;
            }
            if is_triangle(etype) {
                m.elems.reserve(capacity(n, lx.remaining(), 8));
            }
            for _ in 0..n {
                let tag = lx.parse::<u64>("an element tag")?;
                element_nodes(lx, m, tag, etype)?;
            }
        }
    } else {
        let n = lx.count("the number of elements")?;
        for _ in 0..n {
            let tag = lx.parse::<u64>("an element tag")?;
            let etype = lx.parse::<u32>("the element type")?;
            let ntags = lx.count("the number of element tags")?;
            for _ in 0..ntags {
                lx.parse::<i64>("an element tag")?;
            }
            element_nodes(lx, m, tag, etype)?;
        }
    }
    Ok(())
}

fn node_data(lx: &mut Lexer<'_>, m: &mut Msh) -> Result<()> {
    let nstr = lx.count("the number of string tags")?;
    let line = lx.token_line();
    lx.rest_of_line();
    let mut name = None;
    for _ in 0..nstr {
        // `rest_of_line` returns "" at the end of the file: without this check a
        // count of 10^16 string tags would loop that many times on nothing.
        if lx.remaining() == 0 {
            return Err(lx.err(format!(
                "unexpected end of file in the {nstr} string tags of $NodeData"
            )));
        }
        let s = String::from_utf8_lossy(lx.rest_of_line())
            .trim()
            .to_string();
        let s = s.strip_prefix('"').unwrap_or(&s);
        let s = s.strip_suffix('"').unwrap_or(s);
        name.get_or_insert_with(|| s.to_string());
    }
    let nreal = lx.count("the number of real tags")?;
    for _ in 0..nreal {
        lx.real("a real tag")?;
    }
    let nint = lx.count("the number of integer tags")?;
    let mut ints = Vec::new();
    for _ in 0..nint {
        ints.push(lx.parse::<i64>("an integer tag")?);
    }
    if ints.len() < 3 || ints[1] < 1 || ints[2] < 0 {
        return Err(lx.err("$NodeData needs integer tags: step, components (>= 1), count"));
    }
    let (ncomp, n) = (ints[1] as usize, ints[2] as usize);
    let mut entries = Vec::with_capacity(capacity(n, lx.remaining(), 4));
    for _ in 0..n {
        let tag = lx.parse::<u64>("a node tag")?;
        let v = lx.real("a node value")?;
        for _ in 1..ncomp {
            lx.real("a node value")?;
        }
        entries.push((tag, v));
    }
    if ncomp == 1 {
        let name = match name {
            Some(s) if !s.is_empty() => s,
            _ => format!("view{}", m.views.len()),
        };
        m.views.retain(|v| v.name != name);
        m.views.push(View {
            name,
            entries,
            line,
        });
    }
    Ok(())
}

fn finish_mesh(path: &Path, m: Msh) -> Result<SurfaceData> {
    let n = m.vertices.len();
    let index = |tag: u64, line: usize| {
        m.tags
            .get(&tag)
            .copied()
            .ok_or_else(|| Error::parse(path, format!("line {line}: unknown node tag {tag}")))
    };
    let mut triangles = Vec::with_capacity(m.elems.len());
    for (t, line) in &m.elems {
        triangles.push([
            index(t[0], *line)?,
            index(t[1], *line)?,
            index(t[2], *line)?,
        ]);
    }
    let mut point_data = Vec::with_capacity(m.views.len());
    for v in &m.views {
        let mut values = vec![f64::NAN; n];
        for &(tag, x) in &v.entries {
            values[index(tag, v.line)? as usize] = x;
        }
        point_data.push(PointArray {
            name: v.name.clone(),
            values,
        });
    }
    if point_data.len() == 1 && point_data[0].name != "size" {
        point_data[0].name = "size".into();
    }
    Ok(SurfaceData {
        vertices: m.vertices,
        triangles,
        point_data,
    })
}

/// Writes `data` as ASCII MSH 4.1 with one `$NodeData` view per point array.
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    let (n, m) = (data.vertices.len(), data.triangles.len());
    write!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n").map_err(io)?;
    if n == 0 {
        writeln!(w, "0 0 0 0").map_err(io)?;
    } else {
        write!(w, "1 {n} 1 {n}\n2 1 0 {n}\n").map_err(io)?;
        for i in 1..=n {
            writeln!(w, "{i}").map_err(io)?;
        }
        for p in &data.vertices {
            writeln!(w, "{} {} {}", Real(p[0]), Real(p[1]), Real(p[2])).map_err(io)?;
        }
    }
    write!(w, "$EndNodes\n$Elements\n").map_err(io)?;
    if m == 0 {
        writeln!(w, "0 0 0 0").map_err(io)?;
    } else {
        write!(w, "1 {m} 1 {m}\n2 1 2 {m}\n").map_err(io)?;
        for (k, t) in data.triangles.iter().enumerate() {
            writeln!(w, "{} {} {} {}", k + 1, t[0] + 1, t[1] + 1, t[2] + 1).map_err(io)?;
        }
    }
    writeln!(w, "$EndElements").map_err(io)?;
    for a in &data.point_data {
        let name: String = a
            .name
            .chars()
            .map(|c| if c == '"' || c.is_control() { '_' } else { c })
            .collect();
        write!(
            w,
            "$NodeData\n1\n\"{name}\"\n1\n0\n3\n0\n1\n{}\n",
            a.values.len()
        )
        .map_err(io)?;
        for (i, v) in a.values.iter().enumerate() {
            writeln!(w, "{} {}", i + 1, Real(*v)).map_err(io)?;
        }
        writeln!(w, "$EndNodeData").map_err(io)?;
    }
    finish(path, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::off::tests::{same_bits, sample, TempPath};

    #[test]
    fn round_trip_with_views() {
        let t = TempPath::new("rt.msh");
        let mut d = sample();
        d.point_data.push(PointArray {
            name: "my field".into(),
            values: vec![1.0, -2.0, 3.5e-12, 4.0],
        });
        write(&t.0, &d).unwrap();
        let r = read(&t.0).unwrap();
        assert!(same_bits(&r.vertices, &d.vertices));
        assert_eq!(r.triangles, d.triangles);
        assert_eq!(r.point_data.len(), 2);
        for (a, b) in r.point_data.iter().zip(&d.point_data) {
            assert_eq!(a.name, b.name);
            assert!(a
                .values
                .iter()
                .zip(&b.values)
                .all(|(x, y)| x.to_bits() == y.to_bits()));
        }
    }

    #[test]
    fn single_view_becomes_size_and_v2() {
        let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"s\"\n$EndPhysicalNames\n\
                    $Nodes\n4\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 1 1 0\n$EndNodes\n$Elements\n3\n\
                    1 15 2 0 1 10\n2 2 2 1 1 10 20 30\n3 9 2 1 1 20 40 30 5 6 7\n$EndElements\n\
                    $NodeData\n1\n\"h\"\n1\n0.0\n3\n0\n1\n3\n10 0.5\n20 0.25\n40 2\n$EndNodeData\n";
        let d = parse(Path::new("x.msh"), text.as_bytes()).unwrap();
        assert_eq!(d.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(d.point_data[0].name, "size");
        assert_eq!(d.point_data[0].values[..2], [0.5, 0.25]);
        assert!(d.point_data[0].values[2].is_nan());
    }

    #[test]
    fn v41_with_entities_parametric_and_other_elements() {
        let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 0 0 0 1 1 0 0 0\n\
                    $EndEntities\n$Nodes\n2 4 1 4\n0 1 0 1\n1\n0 0 0\n2 1 1 3\n2\n3\n4\n\
                    1 0 0 0.5 0.5\n0 1 0 0.1 0.2\n1 1 0 0.3 0.3\n$EndNodes\n$Elements\n2 3 1 3\n\
                    1 1 1 1\n1 1 2\n2 1 2 2\n2 1 2 3\n3 2 4 3\n$EndElements\n";
        let d = parse(Path::new("x.msh"), text.as_bytes()).unwrap();
        assert_eq!(d.vertices.len(), 4);
        assert_eq!(d.vertices[3], [1.0, 1.0, 0.0]);
        assert_eq!(d.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert!(d.point_data.is_empty());
        // Gmsh repeats the mesh when saving a view with it: read it once.
        let twice = format!("{text}{text}");
        assert_eq!(parse(Path::new("x.msh"), twice.as_bytes()).unwrap(), d);
    }

    #[test]
    fn malformed() {
        let head = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
        let nodes = "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n";
        let p = Path::new("bad.msh");
        for text in [
            String::new(),
            "garbage".into(),
            "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n".into(),
            "$MeshFormat\n4.1 0 99999999999999999999999\n$EndMeshFormat\n".into(),
            "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n".into(),
            format!("{head}$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n"),
            format!("{head}$Nodes\n1 99999999999999 1 2\n2 1 0 99999999999999\n1\n"),
            format!("{head}{nodes}$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 4\n$EndElements\n"),
            format!("{head}{nodes}$Elements\n1 1 1 1\n2 1 2 1\n1 1 2\n$EndElements\n"),
            format!("{head}{nodes}$NodeData\n1\n\"size\"\n1\n0\n3\n0\n1\n1\n7 1.0\n$EndNodeData\n"),
            format!("{head}{nodes}$NodeData\n1\n\"size\"\n1\n0\n3\n0\n1\n2\n1 x\n$EndNodeData\n"),
            format!("{head}$Nodes\n1 2 1 2\n2 1 0 3\n1\n1\n0 0 0\n1 0 0\n$EndNodes\n"),
            format!("{head}$Comments\nno end\n"),
        ] {
            assert!(parse(p, text.as_bytes()).is_err(), "{text:?}");
        }
        let e = parse(
            p,
            format!("{head}{nodes}$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 4\n$EndElements\n").as_bytes(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("line 17"), "{e}");
    }
}
