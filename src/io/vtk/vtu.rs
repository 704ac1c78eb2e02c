//! VTK XML unstructured grid (`.vtu`) through the `vtkio` crate.
//!
//! Reading takes every inline piece of an `UnstructuredGrid` (or `PolyData`) file,
//! ASCII, base64 binary or appended, uncompressed: triangles are kept, polygons,
//! quads and pixels fan-triangulated, triangle strips split, other cells dropped;
//! every 1-component point array (any numeric type) becomes a point array (an
//! array missing from some piece is NaN there). Writing produces one piece with
//! Float64 points, triangle cells and one Float64 point array per point array
//! (base64 binary, no compression), which ParaView opens.

use super::super::off::{check_triangles, create, finish, vertex_index};
use super::super::{PointArray, SurfaceData};
use super::triangulate;
use crate::error::{Error, Result};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    Piece, Version, VertexNumbers, Vtk,
};

/// Cells as `(type, vertices)` after checking the vtkio layout.
fn cell_list(
    path: &Path,
    verts: VertexNumbers,
    types: impl Fn(usize) -> Option<u64>,
    out: &mut Vec<[u64; 3]>,
) -> Result<()> {
    let bad = || Error::parse(path, "inconsistent cell connectivity");
    match verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => {
            let mut start = 0usize;
            for (i, &end) in offsets.iter().enumerate() {
                let end = usize::try_from(end).map_err(|_| bad())?;
                let cell = connectivity.get(start..end).ok_or_else(bad)?;
                triangulate(types(i).ok_or_else(bad)?, cell, out);
                start = end;
            }
        }
        VertexNumbers::Legacy { vertices, .. } => {
            let (mut k, mut i) = (0usize, 0usize);
            while k < vertices.len() {
                let n = vertices[k] as usize;
                let cell = vertices.get(k + 1..k + 1 + n).ok_or_else(bad)?;
                let cell: Vec<u64> = cell.iter().map(|&v| u64::from(v)).collect();
                triangulate(types(i).ok_or_else(bad)?, &cell, out);
                k += 1 + n;
                i += 1;
            }
        }
    }
    Ok(())
}

/// Appends one piece to `out`.
fn add_piece(
    path: &Path,
    out: &mut SurfaceData,
    points: IOBuffer,
    tris: Vec<[u64; 3]>,
    attrs: Attributes,
) -> Result<()> {
    let flat = points
        .cast_into::<f64>()
        .ok_or_else(|| Error::parse(path, "unsupported point coordinate type"))?;
    if flat.len() % 3 != 0 {
        return Err(Error::parse(path, "point array length not a multiple of 3"));
    }
    let base = out.vertices.len();
    let n = flat.len() / 3;
    out.vertices
        .extend(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
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
    let mut arrays: Vec<(String, IOBuffer)> = Vec::new();
    for a in attrs.point {
        match a {
            Attribute::DataArray(DataArray { name, elem, data }) if elem.num_comp() == 1 => {
                arrays.push((name, data))
            }
            Attribute::Field { data_array, .. } => arrays.extend(
                data_array
                    .into_iter()
                    .filter(|f| f.elem == 1)
                    .map(|f| (f.name, f.data)),
            ),
            _ => {}
        }
    }
    for (name, buf) in arrays {
        let Some(values) = buf.cast_into::<f64>().filter(|v| v.len() == n) else {
            continue;
        };
        let pos = out.point_data.iter().position(|a| a.name == name);
        let a = match pos {
            Some(k) => &mut out.point_data[k],
            None => {
                out.point_data.push(PointArray {
                    name,
                    values: vec![f64::NAN; base],
                });
                out.point_data.last_mut().expect("just pushed")
            }
        };
        a.values.truncate(base);
        a.values.extend(values);
    }
    for a in &mut out.point_data {
        a.values.resize(total, f64::NAN);
    }
    Ok(())
}

fn inline<P>(path: &Path, p: Piece<P>) -> Result<P> {
    match p {
        Piece::Inline(p) => Ok(*p),
        _ => Err(Error::parse(
            path,
            "pieces stored in other files are not supported",
        )),
    }
}

/// Reads the VTK XML file `path`.
pub(crate) fn read_vtu(path: &Path) -> Result<SurfaceData> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let vtk = Vtk::parse_xml(BufReader::new(file))
        .map_err(|e| Error::parse(path, format!("invalid VTK XML: {e}")))?;
    let mut out = SurfaceData::default();
    match vtk.data {
        DataSet::UnstructuredGrid { pieces, .. } => {
            for p in pieces {
                let p = inline(path, p)?;
                let types: Vec<u64> = p.cells.types.iter().map(|&t| t as u64).collect();
                let mut tris = Vec::new();
                cell_list(
                    path,
                    p.cells.cell_verts,
                    |i| types.get(i).copied(),
                    &mut tris,
                )?;
                add_piece(path, &mut out, p.points, tris, p.data)?;
            }
        }
        DataSet::PolyData { pieces, .. } => {
            for p in pieces {
                let p = inline(path, p)?;
                let mut tris = Vec::new();
                for (cells, ty) in [(p.polys, 7), (p.strips, 6)] {
                    if let Some(c) = cells {
                        cell_list(path, c, |_| Some(ty), &mut tris)?;
                    }
                }
                add_piece(path, &mut out, p.points, tris, p.data)?;
            }
        }
        _ => {
            return Err(Error::parse(
                path,
                "not an UnstructuredGrid or PolyData file",
            ))
        }
    }
    Ok(out)
}

/// Writes `data` as a VTK XML unstructured grid (Float64, uncompressed).
pub(crate) fn write_vtu(path: &Path, data: &SurfaceData) -> Result<()> {
    check_triangles(data)?;
    let m = data.triangles.len() as u64;
    let points: Vec<f64> = data.vertices.iter().flatten().copied().collect();
    let connectivity: Vec<u64> = data.triangles.iter().flatten().map(|&i| i.into()).collect();
    let point = data
        .point_data
        .iter()
        .map(|a| {
            Attribute::DataArray(DataArray {
                name: a.name.clone(),
                elem: ElementType::Scalars {
                    num_comp: 1,
                    lookup_table: None,
                },
                data: IOBuffer::F64(a.values.clone()),
            })
        })
        .collect();
    let vtk = Vtk {
        version: Version::new((1, 0)),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(vtkio::model::UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets: (1..=m).map(|k| 3 * k).collect(),
                },
                types: vec![CellType::Triangle; m as usize],
            },
            data: Attributes {
                point,
                cell: Vec::new(),
            },
        }),
    };
    let mut w = create(path)?;
    vtk.write_xml(&mut w)
        .map_err(|e| Error::io(path, std::io::Error::other(e.to_string())))?;
    finish(path, w)
}
