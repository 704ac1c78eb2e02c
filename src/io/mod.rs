//! Readers and writers for triangle surface files.
//!
//! Every reader returns a [`SurfaceData`]: vertex coordinates (f64), triangles (u32
//! indices, polygons fan-triangulated), and per-vertex scalar arrays (`size` among
//! them when the file carries one). STL has no shared vertices: its reader returns
//! one vertex per triangle corner; welding is the grid builder's job
//! ([`crate::mesh::weld`]).
//!
//! | format | read | write | sizes |
//! |---|---|---|---|
//! | STL (ASCII, binary) | yes | yes (binary) | no |
//! | OBJ | yes | yes | no |
//! | OFF | yes | yes | no |
//! | PLY (ASCII, binary) | yes | yes | vertex property `size` |
//! | Gmsh MSH 4.1 | yes | yes | NodeData view named `size` |
//! | VTK legacy `.vtk` | yes | yes | POINT_DATA arrays |
//! | VTK XML `.vtu` | yes | yes | PointData arrays |
//! | Medit `.mesh` + `.sol` | yes | yes | the `.sol` scalar |
//! | abgs binary `.abgs` ([`abgs_bin`]) | yes | yes | sizes, arrays, BVH layout |

use crate::error::{Error, Result};
use std::path::Path;

pub mod abgs_bin;
mod medit;
mod msh;
mod obj;
mod off;
mod ply;
mod stl;
mod vtk;

/// A surface as read from or written to a file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceData {
    /// Vertex coordinates.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices (not validated: the grid builder checks them).
    pub triangles: Vec<[u32; 3]>,
    /// Named per-vertex scalar arrays, each of length `vertices.len()`.
    pub point_data: Vec<PointArray>,
}

/// A named scalar value per vertex.
#[derive(Debug, Clone, PartialEq)]
pub struct PointArray {
    /// Array name (`"size"` is the element size).
    pub name: String,
    /// One value per vertex.
    pub values: Vec<f64>,
}

impl SurfaceData {
    /// The per-vertex array called `name`, if present.
    pub fn point_array(&self, name: &str) -> Option<&[f64]> {
        self.point_data
            .iter()
            .find(|a| a.name == name)
            .map(|a| a.values.as_slice())
    }
}

/// The file formats abgs knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stereolithography, ASCII or binary (`.stl`).
    Stl,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Object File Format (`.off`).
    Off,
    /// Polygon File Format (`.ply`).
    Ply,
    /// Gmsh MSH 4.1 (`.msh`).
    Msh,
    /// VTK legacy unstructured grid / polydata (`.vtk`).
    Vtk,
    /// VTK XML unstructured grid (`.vtu`).
    Vtu,
    /// Medit `.mesh` with an optional `.sol` beside it.
    Medit,
    /// abgs's own binary form of a whole grid (`.abgs`, [`abgs_bin`]).
    Abgs,
}

impl Format {
    /// The format named by the extension of `path` (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "stl" => Format::Stl,
            "obj" => Format::Obj,
            "off" => Format::Off,
            "ply" => Format::Ply,
            "msh" => Format::Msh,
            "vtk" => Format::Vtk,
            "vtu" => Format::Vtu,
            "mesh" => Format::Medit,
            "abgs" => Format::Abgs,
            _ => {
                return Err(Error::UnsupportedFormat(format!(
                "'{}': unknown extension '{}' (expected stl, obj, off, ply, msh, vtk, vtu, mesh or abgs)",
                path.display(),
                ext
            )))
            }
        })
    }
}

/// Reads the surface in `path`, format chosen by extension.
pub fn read(path: &Path) -> Result<SurfaceData> {
    let data = match Format::from_path(path)? {
        Format::Stl => stl::read(path)?,
        Format::Obj => obj::read(path)?,
        Format::Off => off::read(path)?,
        Format::Ply => ply::read(path)?,
        Format::Msh => msh::read(path)?,
        Format::Vtk => vtk::read_legacy(path)?,
        Format::Vtu => vtk::read_vtu(path)?,
        Format::Medit => medit::read(path)?,
        Format::Abgs => abgs_bin::read(path)?.to_surface(),
    };
    for a in &data.point_data {
        if a.values.len() != data.vertices.len() {
            return Err(Error::parse(
                path,
                format!(
                    "point array '{}' has {} values for {} vertices",
                    a.name,
                    a.values.len(),
                    data.vertices.len()
                ),
            ));
        }
    }
    Ok(data)
}

/// Writes `data` to `path`, format chosen by extension.
///
/// Formats that cannot store per-vertex arrays (STL, OBJ, OFF) drop them.
pub fn write(path: &Path, data: &SurfaceData) -> Result<()> {
    for a in &data.point_data {
        if a.values.len() != data.vertices.len() {
            return Err(Error::InvalidArgument(format!(
                "point array '{}' has {} values for {} vertices",
                a.name,
                a.values.len(),
                data.vertices.len()
            )));
        }
    }
    match Format::from_path(path)? {
        Format::Stl => stl::write(path, data),
        Format::Obj => obj::write(path, data),
        Format::Off => off::write(path, data),
        Format::Ply => ply::write(path, data),
        Format::Msh => msh::write(path, data),
        Format::Vtk => vtk::write_legacy(path, data),
        Format::Vtu => vtk::write_vtu(path, data),
        Format::Medit => medit::write(path, data),
        Format::Abgs => {
            // A grid of the data as it is (no welding, no re-orienting).
            let options = crate::mesh::BuildOptions {
                weld_relative_tolerance: None,
                orient: false,
            };
            abgs_bin::write(
                path,
                &crate::mesh::Grid::from_surface(data.clone(), &options)?,
            )
        }
    }
}
