//! Polygon File Format (`.ply`) through the `ply-rs-bw` crate.
//!
//! Reading accepts ASCII and binary (little or big endian) files. The `vertex`
//! element must have scalar `x`, `y`, `z` (any numeric type); every other scalar
//! vertex property except `nx`, `ny`, `nz` (e.g. `size`, but also colours) becomes a
//! point array of its name. The `face` element's `vertex_indices` (or
//! `vertex_index`) list is fan-triangulated; faces of fewer than three vertices are
//! skipped. Other elements are read past and dropped.
//!
//! Writing produces binary little endian: `x y z` and every point array as `double`
//! vertex properties (names sanitised: whitespace becomes `_`), faces as
//! `list uchar int vertex_indices`.

use super::off::{capacity, check_triangles, create, finish, vertex_index};
use super::{PointArray, SurfaceData};
use crate::error::{Error, Result};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult,
    PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// A vertex as read: `x y z`, then the other scalar properties in header order.
struct InVertex {
    xyz: [f64; 3],
    extra: Vec<f64>,
}

impl PropertyAccess for InVertex {
    fn new() -> Self {
        InVertex {
            xyz: [0.0; 3],
            extra: Vec::new(),
        }
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        let v = match p {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => return PropertyAccessResult::Ignored,
        };
        match name {
            "x" => self.xyz[0] = v,
            "y" => self.xyz[1] = v,
            "z" => self.xyz[2] = v,
            _ => self.extra.push(v),
        }
        PropertyAccessResult::Set
    }
}

/// A face as read: its vertex indices (negative ones kept to be rejected).
struct InFace(Vec<i64>);

fn widen<T: Into<i64>>(v: Vec<T>) -> Vec<i64> {
    v.into_iter().map(Into::into).collect()
}

impl PropertyAccess for InFace {
    fn new() -> Self {
        InFace(Vec::new())
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        if name != "vertex_indices" && name != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        self.0 = match p {
            Property::ListChar(v) => widen(v),
            Property::ListUChar(v) => widen(v),
            Property::ListShort(v) => widen(v),
            Property::ListUShort(v) => widen(v),
            Property::ListInt(v) => widen(v),
            Property::ListUInt(v) => widen(v),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// An element that is read past and dropped.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// Reads the PLY file `path`.
pub(crate) fn read(path: &Path) -> Result<SurfaceData> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map(|m| m.len() as usize).unwrap_or(0);
    let mut reader = Reader::new(BufReader::new(file));
    let perr = |e: ply_rs_bw::parser::ParseError| Error::parse(path, e.to_string());
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(perr)?;
    let mut data = SurfaceData::default();
    let mut vertex_seen = false;
    let mut faces: Vec<InFace> = Vec::new();
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" if !vertex_seen => {
                vertex_seen = true;
                let mut extra_names = Vec::new();
                for c in ["x", "y", "z"] {
                    match def.properties.get(c).map(|p| &p.data_type) {
                        Some(PropertyType::Scalar(_)) => {}
                        _ => return Err(Error::parse(path, format!("vertex has no scalar '{c}'"))),
                    }
                }
                for (pname, p) in &def.properties {
                    if matches!(p.data_type, PropertyType::Scalar(_))
                        && !["x", "y", "z"].contains(&pname.as_str())
                    {
                        extra_names.push(pname.clone());
                    }
                }
                let verts = Parser::<InVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(perr)?;
                data.vertices = verts.iter().map(|v| v.xyz).collect();
                for (k, pname) in extra_names.into_iter().enumerate() {
                    if ["nx", "ny", "nz"].contains(&pname.as_str()) {
                        continue;
                    }
                    let values = verts
                        .iter()
                        .map(|v| v.extra.get(k).copied().unwrap_or(f64::NAN))
                        .collect();
                    data.point_data.push(PointArray {
                        name: pname,
                        values,
                    });
                }
            }
            "face" if faces.is_empty() => {
                if !def.properties.contains_key("vertex_indices")
                    && !def.properties.contains_key("vertex_index")
                {
                    return Err(Error::parse(path, "face has no vertex_indices list"));
                }
                faces = Parser::<InFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(perr)?;
            }
            // A binary element without properties takes no bytes, whatever its
            // count: nothing to skip. Reading it element by element looped
            // `count` times on nothing (fuzzing found a count of 1.3e14). ASCII
            // needs no such care: each element is a line, and the end of the file
            // ends the loop.
            _ if def.properties.is_empty() && !matches!(header.encoding, Encoding::Ascii) => {}
            _ => {
                Parser::<Skip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(perr)?;
            }
        }
    }
    if !vertex_seen {
        return Err(Error::parse(path, "no vertex element"));
    }
    let n = data.vertices.len();
    data.triangles.reserve(capacity(faces.len(), len, 4));
    for (k, f) in faces.iter().enumerate() {
        let mut idx = Vec::with_capacity(f.0.len());
        for &i in &f.0 {
            let v = u64::try_from(i).ok().and_then(|i| vertex_index(i, n));
            idx.push(v.ok_or_else(|| {
                Error::parse(
                    path,
                    format!("face {k}: vertex index {i} out of range (0..{n})"),
                )
            })?);
        }
        for j in 2..idx.len() {
            data.triangles.push([idx[0], idx[j - 1], idx[j]]);
        }
    }
    Ok(data)
}

/// A vertex being written: values by property name.
struct OutVertex {
    names: Vec<String>,
    values: Vec<f64>,
}

impl PropertyAccess for OutVertex {
    fn new() -> Self {
        OutVertex {
            names: Vec::new(),
            values: Vec::new(),
        }
    }

    fn get_double(&self, name: &str) -> Option<f64> {
        let k = self.names.iter().position(|n| n == name)?;
        self.values.get(k).copied()
    }
}

/// A face being written.
struct OutFace([i32; 3]);

impl PropertyAccess for OutFace {
    fn new() -> Self {
        OutFace([0; 3])
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(&self.0[..])
    }
}

/// Property names for the point arrays of `data`: whitespace replaced, made unique.
fn array_names(data: &SurfaceData) -> Vec<String> {
    let mut names: Vec<String> = vec!["x".into(), "y".into(), "z".into()];
    for a in &data.point_data {
        let mut s: String = a
            .name
            .chars()
            .map(|c| {
                if c.is_whitespace() || c.is_control() {
                    '_'
                } else {
                    c
                }
            })
            .collect();
        if s.is_empty() {
            s.push_str("array");
        }
        while names.contains(&s) {
            s.push('_');
        }
        names.push(s);
    }
    names
}

/// Writes `data` as binary little endian PLY, point arrays as double properties.
pub(crate) fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    if data.vertices.len() > i32::MAX as usize {
        return Err(Error::InvalidArgument(
            "PLY: too many vertices for int indices".into(),
        ));
    }
    let names = array_names(data);
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push("written by abgs".into());
    let mut vdef = ElementDef::new("vertex".into());
    vdef.count = data.vertices.len();
    for n in &names {
        vdef.properties.add(PropertyDef::new(
            n.clone(),
            PropertyType::Scalar(ScalarType::Double),
        ));
    }
    let mut fdef = ElementDef::new("face".into());
    fdef.count = data.triangles.len();
    fdef.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::Int),
    ));
    header.elements.add(vdef.clone());
    header.elements.add(fdef.clone());

    let mut w = create(path)?;
    let io = |e| Error::io(path, e);
    let vw = Writer::<OutVertex>::new();
    vw.write_header(&mut w, &header).map_err(io)?;
    let mut v = OutVertex {
        names,
        values: Vec::new(),
    };
    for (i, p) in data.vertices.iter().enumerate() {
        v.values.clear();
        v.values.extend_from_slice(p);
        v.values.extend(data.point_data.iter().map(|a| a.values[i]));
        vw.write_little_endian_element(&mut w, &v, &vdef)
            .map_err(io)?;
    }
    let fw = Writer::<OutFace>::new();
    for t in &data.triangles {
        // check_triangles and the vertex count bound make these casts exact.
        let f = OutFace(t.map(|i| i as i32));
        fw.write_little_endian_element(&mut w, &f, &fdef)
            .map_err(io)?;
    }
    finish(path, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::off::tests::{same_bits, sample, TempPath};

    #[test]
    fn round_trip_binary_with_size() {
        let t = TempPath::new("rt.ply");
        let mut d = sample();
        d.point_data.push(PointArray {
            name: "other field".into(),
            values: vec![1.0, 2.0, 3.0, -4.5],
        });
        write(&t.0, &d).unwrap();
        let r = read(&t.0).unwrap();
        assert!(same_bits(&r.vertices, &d.vertices));
        assert_eq!(r.triangles, d.triangles);
        assert_eq!(r.point_data.len(), 2);
        assert_eq!(r.point_data[1].name, "other_field");
        for (a, b) in r.point_data.iter().zip(&d.point_data) {
            assert!(a
                .values
                .iter()
                .zip(&b.values)
                .all(|(x, y)| x.to_bits() == y.to_bits()));
        }
    }

    #[test]
    fn ascii_float_quads_normals_and_other_elements() {
        let t = TempPath::new("ascii.ply");
        let text = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\n\
                    property float y\nproperty float z\nproperty float nx\nproperty float ny\n\
                    property float nz\nproperty uchar red\nproperty float size\n\
                    element face 2\nproperty list uchar uint vertex_index\nproperty uchar flags\n\
                    element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n\
                    0 0 0 0 0 1 255 0.5\n1 0 0 0 0 1 0 0.25\n1 1 0 0 0 1 0 1\n0 1 0 0 0 1 0 2\n\
                    4 0 1 2 3 7\n2 0 1 0\n0 1\n";
        std::fs::write(&t.0, text).unwrap();
        let d = read(&t.0).unwrap();
        assert_eq!(d.vertices[2], [1.0, 1.0, 0.0]);
        assert_eq!(d.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let names: Vec<_> = d.point_data.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["red", "size"]);
        assert_eq!(d.point_array("size").unwrap(), [0.5, 0.25, 1.0, 2.0]);
    }

    #[test]
    fn malformed() {
        let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                    end_header\n";
        for text in [
            String::new(),
            "garbage\n".into(),
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0\n0\n0\n"
                .into(),
            format!("{head}0 0 0\n1 0 0\n"),
            format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
            format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
            format!("{head}0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"),
            format!("{head}0 0 0\n1 0 0\n0 1 0\n200 0 1 2\n"),
            head.replace("vertex 3", "vertex 99999999999999999"),
            head.replace("ascii", "binary_little_endian") + "\x01\x02",
        ] {
            let t = TempPath::new("bad.ply");
            std::fs::write(&t.0, &text).unwrap();
            assert!(read(&t.0).is_err(), "{text:?}");
        }
    }
}
