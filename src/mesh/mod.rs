//! The background grid: an immutable triangle surface with one size per vertex,
//! its adjacency, its BVH and the report of what was found on input.

mod contact_lists;
pub mod feature_lines;
pub mod features;
pub mod halfedge;
mod restore;
pub mod shape;
pub(crate) mod stats;
pub(crate) mod topology;
mod validate;
pub mod weld;

pub(crate) use contact_lists::MAX_LIST as MAX_CONTACT_LIST;
pub use features::Features;
pub use restore::{GridParts, InputHistory};
pub use stats::{AngleStats, GridStats};
pub use topology::Topology;
pub use validate::ValidationReport;

use crate::error::{Error, Result};
use crate::geometry::Aabb;
use crate::io::{Format, PointArray, SurfaceData};
use crate::spatial::Bvh;
use std::path::Path;

/// Sheets closer than this fraction of the bounding-box diagonal are in
/// contact (touching bodies, coincident faces), not apart: the sizing's
/// default contact gap and `hmin` (1/2000), the queries' tie tolerance
/// between bodies, and the metrics' contact distance.
pub const CONTACT_FRACTION: f64 = 1.0 / 2000.0;

/// How a grid is built from raw data.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildOptions {
    /// Weld vertices closer than this fraction of the bounding-box diagonal;
    /// `None` keeps the vertices as given (indices stay stable).
    pub weld_relative_tolerance: Option<f64>,
    /// Make triangle orientation consistent per body (outward when closed).
    pub orient: bool,
}

impl Default for BuildOptions {
    /// No welding, orientation fixed.
    fn default() -> Self {
        BuildOptions {
            weld_relative_tolerance: None,
            orient: true,
        }
    }
}

impl BuildOptions {
    /// Default relative weld tolerance for triangle soups (STL): 1e-7 of the diagonal.
    pub const SOUP_WELD_TOLERANCE: f64 = 1e-7;

    /// Options suited to a file format: STL (a soup) is welded, indexed formats are not.
    pub fn for_format(format: Format) -> BuildOptions {
        BuildOptions {
            weld_relative_tolerance: (format == Format::Stl).then_some(Self::SOUP_WELD_TOLERANCE),
            orient: true,
        }
    }
}

/// A background grid. Immutable except for its sizes ([`Grid::set_sizes`]);
/// any number of threads may query it at once.
#[derive(Debug, Clone)]
pub struct Grid {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    sizes: Option<Vec<f64>>,
    /// Lower bound of the size over each BVH node (for volume queries).
    node_min_size: Vec<f64>,
    extra: Vec<PointArray>,
    topology: Topology,
    bvh: Bvh,
    bbox: Aabb,
    report: ValidationReport,
    /// Per triangle: may another body's face lie within the contact gap of
    /// it? Computed on first use ([`Grid::contact_faces`]).
    contact_faces: std::sync::OnceLock<Vec<bool>>,
    /// Per contact face: the other bodies' faces that may lie within the
    /// contact gap of it. Computed on first use ([`Grid::contact_lists`]).
    contact_lists: std::sync::OnceLock<contact_lists::ContactLists>,
    /// Per BVH node: the body of every triangle below it, or
    /// [`crate::spatial::MIXED_LABEL`]. Computed on first use
    /// ([`Grid::node_bodies`]).
    node_bodies: std::sync::OnceLock<Vec<u32>>,
    /// The certified hinted search's table (per BVH slot: the faces across
    /// its edges and its prism clearance). Computed on first use
    /// ([`Grid::prisms`]).
    prisms: std::sync::OnceLock<crate::spatial::Prisms>,
    /// Process-unique id (a clone keeps it): keys the thread's record of
    /// its last plain query (module `query::recent`).
    id: u64,
}

/// The arrays of a grid once checked, before its adjacency and hierarchy.
struct Checked {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    sizes: Option<Vec<f64>>,
    extra: Vec<PointArray>,
}

/// Smallest and largest bounding-box diagonal a grid may have. The pipeline
/// forms products of up to four lengths (areas squared, the quadrics of the
/// QEM baseline, cotangent weights over areas); inside this range every such
/// product, L⁴ ∈ [1e-300, 1e300], stays a normal f64, so a model's results do
/// not depend on its scale. Outside it, rescale the coordinates.
pub const EXTENT_RANGE: [f64; 2] = [1e-75, 1e75];

/// Checks a model's bounding-box diagonal against [`EXTENT_RANGE`] (vertices
/// are already within ±[`crate::geometry::MAX_COORDINATE`], so it is finite; a
/// single point, extent 0, is left to the degenerate-triangle checks, which report an empty
/// grid). The diagonal is bracketed by the largest side `m` (m ≤ d ≤ √3·m),
/// which neither underflows nor overflows where the squared sum would.
fn check_extent(bbox: &Aabb) -> Result<()> {
    let [lo, hi] = EXTENT_RANGE;
    let m = (0..3).fold(0.0f64, |m, k| m.max(bbox.max[k] - bbox.min[k]));
    let diagonal = m * 3f64.sqrt();
    if m == 0.0 || (m >= lo && diagonal <= hi) {
        return Ok(());
    }
    Err(Error::InvalidArgument(format!(
        "the model's bounding-box diagonal is {diagonal:e}; it must lie in [{lo:e}, {hi:e}] \
         (rescale the coordinates) so that lengths to the fourth power stay finite and non-zero"
    )))
}

impl Grid {
    /// Builds a grid from vertices, triangles and optional per-vertex sizes.
    ///
    /// Errors on a non-finite coordinate (or one beyond
    /// [`crate::geometry::MAX_COORDINATE`]), an out-of-range index, a size that is not
    /// finite and > 0, a size array of the wrong length, or when no triangle is
    /// left. Zero-area triangles are dropped and counted in [`Grid::report`].
    /// O(F log F).
    pub fn from_arrays(
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        sizes: Option<Vec<f64>>,
        options: &BuildOptions,
    ) -> Result<Grid> {
        let mut point_data = Vec::new();
        if let Some(s) = sizes {
            point_data.push(PointArray {
                name: "size".into(),
                values: s,
            });
        }
        Grid::from_surface(
            SurfaceData {
                vertices,
                triangles,
                point_data,
            },
            options,
        )
    }

    /// Builds a grid from a [`SurfaceData`]; its point array `size`, if any,
    /// becomes the sizes, other arrays are kept and written back on save.
    pub fn from_surface(data: SurfaceData, options: &BuildOptions) -> Result<Grid> {
        let SurfaceData {
            mut vertices,
            mut triangles,
            mut point_data,
        } = data;
        check_arrays(&vertices, &triangles, &point_data)?;
        let sizes = match point_data.iter().position(|a| a.name == "size") {
            Some(i) => {
                let s = point_data.remove(i).values;
                check_sizes(&s, vertices.len())?;
                Some(s)
            }
            None => None,
        };
        let mut report = ValidationReport {
            input_vertices: vertices.len(),
            input_triangles: triangles.len(),
            ..Default::default()
        };
        let bbox = Aabb::from_points(&vertices);
        check_extent(&bbox)?;
        let mut sizes = sizes;
        if let Some(rel) = options.weld_relative_tolerance {
            if !(rel.is_finite() && rel >= 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "weld tolerance {rel} must be finite and >= 0"
                )));
            }
            let (kept, remap) = weld::weld(&vertices, rel * bbox.diagonal());
            report.welded_vertices = vertices.len() - kept.len();
            if report.welded_vertices > 0 {
                let pick = |vals: &[f64]| {
                    let mut out = vec![f64::NAN; kept.len()];
                    for (i, &r) in remap.iter().enumerate().rev() {
                        out[r as usize] = vals[i];
                    }
                    out
                };
                sizes = sizes.map(|s| pick(&s));
                for a in &mut point_data {
                    a.values = pick(&a.values);
                }
                for t in &mut triangles {
                    *t = t.map(|v| remap[v as usize]);
                }
                vertices = kept;
            }
        }
        let (mut kept, repeated, zero) = validate::drop_degenerate(&vertices, &triangles);
        report.dropped_repeated_index = repeated;
        report.dropped_zero_area = zero;
        if kept.is_empty() {
            return Err(Error::Empty(format!(
                "all {} triangles are degenerate",
                triangles.len()
            )));
        }
        let mut topology = Topology::build(vertices.len(), &kept);
        if options.orient {
            let (flipped, bad) = validate::orient(&vertices, &mut kept, &topology);
            report.flipped_triangles = flipped;
            report.non_orientable_bodies = bad;
            if flipped > 0 {
                topology = Topology::build(vertices.len(), &kept);
            }
        }
        let triangles = kept;
        let bvh = Bvh::build(&vertices, &triangles);
        Ok(Grid::assemble(
            Checked {
                vertices,
                triangles,
                sizes,
                extra: point_data,
            },
            topology,
            bvh,
            report,
        ))
    }

    /// The grid over checked parts (indices in range, no degenerate
    /// triangle, sizes valid) with their adjacency and hierarchy: fills the
    /// report's counts that follow from the triangles (the input history —
    /// input counts, welded, dropped, flipped — is the caller's).
    /// O(F log F).
    fn assemble(
        parts: Checked,
        topology: Topology,
        bvh: Bvh,
        mut report: ValidationReport,
    ) -> Grid {
        let Checked {
            vertices,
            triangles,
            sizes,
            extra,
        } = parts;
        report.duplicate_triangles = validate::count_duplicates(&triangles);
        report.boundary_edges = topology.boundary_edge_count();
        report.non_manifold_edges = topology.non_manifold_edge_count();
        report.non_manifold_vertices =
            validate::count_non_manifold_vertices(&topology, vertices.len());
        report.bodies = topology.body_count as usize;
        report.unreferenced_vertices = (0..vertices.len())
            .filter(|&v| topology.faces_of_vertex(v).is_empty())
            .count();
        let mut open = vec![false; report.bodies];
        for e in 0..topology.edges.len() {
            let ef = topology.faces_of_edge(e);
            if ef.len() == 1 {
                open[topology.face_body[ef[0] as usize] as usize] = true;
            }
        }
        report.open_bodies = open.iter().filter(|&&o| o).count();
        report.sliver_triangles = stats::count_slivers(&vertices, &triangles, 1.0);
        let mut grid = Grid {
            bbox: Aabb::from_points(&vertices),
            vertices,
            triangles,
            sizes: None,
            node_min_size: Vec::new(),
            extra,
            topology,
            bvh,
            report,
            contact_faces: std::sync::OnceLock::new(),
            contact_lists: std::sync::OnceLock::new(),
            node_bodies: std::sync::OnceLock::new(),
            prisms: std::sync::OnceLock::new(),
            id: crate::query::new_grid_id(),
        };
        if let Some(s) = sizes {
            grid.install_sizes(s);
        }
        grid
    }

    /// Reads a grid from a file (format by extension). STL is welded with
    /// [`BuildOptions::SOUP_WELD_TOLERANCE`]; a `size` point array becomes the sizes.
    /// An `.abgs` file ([`crate::io::abgs_bin`]) gives back the grid that was
    /// saved, hierarchy and input report included.
    pub fn load(path: &Path) -> Result<Grid> {
        let format = Format::from_path(path)?;
        if format == Format::Abgs {
            return crate::io::abgs_bin::read(path);
        }
        let data = crate::io::read(path)?;
        Grid::from_surface(data, &BuildOptions::for_format(format))
    }

    /// Writes the grid (sizes as point array `size`, plus any other arrays read
    /// with it) to `path`, format by extension; `.abgs` stores the whole grid
    /// ([`crate::io::abgs_bin`]).
    pub fn save(&self, path: &Path) -> Result<()> {
        if Format::from_path(path)? == Format::Abgs {
            return crate::io::abgs_bin::write(path, self);
        }
        crate::io::write(path, &self.to_surface())
    }

    /// The grid as plain data (a copy), sizes first among the point arrays.
    pub fn to_surface(&self) -> SurfaceData {
        let mut point_data = Vec::new();
        if let Some(s) = &self.sizes {
            point_data.push(PointArray {
                name: "size".into(),
                values: s.clone(),
            });
        }
        point_data.extend(self.extra.iter().cloned());
        SurfaceData {
            vertices: self.vertices.clone(),
            triangles: self.triangles.clone(),
            point_data,
        }
    }

    /// Replaces the sizes (one per vertex, each finite and > 0). O(V + F).
    pub fn set_sizes(&mut self, sizes: Vec<f64>) -> Result<()> {
        check_sizes(&sizes, self.vertices.len())?;
        self.install_sizes(sizes);
        Ok(())
    }

    /// Removes the sizes.
    pub fn clear_sizes(&mut self) {
        self.sizes = None;
        self.node_min_size.clear();
    }

    fn install_sizes(&mut self, sizes: Vec<f64>) {
        let tri_min: Vec<f64> = self
            .triangles
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| sizes[v as usize])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        self.node_min_size = self.bvh.node_minima(&tri_min);
        self.sizes = Some(sizes);
    }

    /// Adds (or replaces) a named per-vertex array kept alongside the grid and
    /// written on save. The name `size` is reserved: use [`Grid::set_sizes`].
    pub fn set_point_array(&mut self, name: &str, values: Vec<f64>) -> Result<()> {
        if name == "size" {
            return Err(Error::InvalidArgument(
                "'size' is reserved; use set_sizes".into(),
            ));
        }
        if values.len() != self.vertices.len() {
            return Err(Error::InvalidArgument(format!(
                "array '{name}' has {} values for {} vertices",
                values.len(),
                self.vertices.len()
            )));
        }
        self.extra.retain(|a| a.name != name);
        self.extra.push(PointArray {
            name: name.into(),
            values,
        });
        Ok(())
    }

    /// Vertex coordinates.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }
    /// Triangles (vertex indices).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    /// Per-vertex sizes, if set.
    pub fn sizes(&self) -> Option<&[f64]> {
        self.sizes.as_deref()
    }
    /// Per-vertex arrays other than sizes.
    pub fn point_arrays(&self) -> &[PointArray] {
        &self.extra
    }
    /// Adjacency tables.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }
    /// The spatial index.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }
    /// Per-node size lower bounds (empty without sizes).
    pub(crate) fn node_min_size(&self) -> &[f64] {
        &self.node_min_size
    }
    /// Per triangle: may a face of another body lie within the contact gap
    /// ([`Grid::contact_gap`]) of some point of it? Conservative (a sphere
    /// around the triangle, padded by 1e-9 relative, is tested), so a `false`
    /// is certain: the tie rule and the simplifier's agreed sizes search for
    /// other bodies only on `true` triangles. Empty for a grid of one body.
    /// Computed once, on first use: O(F log F), deterministic; parallel
    /// unless first called on a rayon worker thread (see
    /// `on_rayon_worker`).
    pub fn contact_faces(&self) -> &[bool] {
        self.contact_faces.get_or_init(|| {
            use rayon::prelude::*;
            let topo = self.topology();
            if topo.body_count < 2 {
                return Vec::new();
            }
            let gap = self.contact_gap();
            let body = &topo.face_body;
            let nodes = self.node_bodies();
            let flag = |f: usize| {
                let (m, r) = self.centroid_ball(f);
                let own = body[f];
                self.bvh()
                    .closest_filtered_within_pruned(
                        m,
                        (r + gap) * (1.0 + 1e-9),
                        |t| body[t as usize] != own,
                        |n| nodes[n] != own,
                    )
                    .is_some()
            };
            let faces = 0..self.triangles().len();
            if on_rayon_worker() {
                faces.map(flag).collect()
            } else {
                faces.into_par_iter().map(flag).collect()
            }
        })
    }

    /// Centroid of triangle `f`, `(a + b + c) / 3` per coordinate (the
    /// contact lists' bounds are measured from exactly this point). O(1).
    #[inline]
    pub(crate) fn centroid(&self, f: usize) -> [f64; 3] {
        let v = &self.vertices;
        centroid3(self.triangles[f].map(|i| v[i as usize]))
    }

    /// Centroid `m` of triangle `f` and its largest distance `r` to a corner:
    /// every point of the triangle lies within `r` of `m`. O(1).
    pub(crate) fn centroid_ball(&self, f: usize) -> ([f64; 3], f64) {
        let v = &self.vertices;
        let [a, b, c] = self.triangles[f].map(|i| v[i as usize]);
        let m = centroid3([a, b, c]);
        let r = [a, b, c]
            .iter()
            .map(|&q| crate::geometry::norm(crate::geometry::sub(q, m)))
            .fold(0.0, f64::max);
        (m, r)
    }

    /// Per contact face, the other bodies' faces that may lie within the
    /// contact gap of any of its points (see [`contact_lists`]). Computed
    /// once, on first use: O(Fc log F) for Fc contact faces; parallel unless
    /// first called on a rayon worker thread (see [`on_rayon_worker`]).
    pub(crate) fn contact_lists(&self) -> &contact_lists::ContactLists {
        self.contact_lists
            .get_or_init(|| contact_lists::ContactLists::build(self))
    }

    /// Per BVH node: the body every triangle below it belongs to, or
    /// [`crate::spatial::MIXED_LABEL`] where they differ. The searches for
    /// *other* bodies (the tie rule, [`Grid::contact_faces`]) skip the
    /// subtrees of bodies they exclude with it: on a point of a body, most
    /// nodes within reach hold only that body's own faces. Computed once, on
    /// first use: O(nodes).
    pub(crate) fn node_bodies(&self) -> &[u32] {
        self.node_bodies
            .get_or_init(|| self.bvh.node_labels(&self.topology.face_body))
    }

    /// The grid as the certified hinted search reads it
    /// ([`crate::spatial::PrismMesh`]).
    pub(crate) fn prism_mesh(&self) -> crate::spatial::PrismMesh<'_> {
        crate::spatial::PrismMesh {
            face_edges: &self.topology.face_edges,
            edge_face_offsets: &self.topology.edge_face_offsets,
            edge_faces: &self.topology.edge_faces,
            bvh: &self.bvh,
        }
    }

    /// The certified hinted search's table
    /// ([`crate::spatial::PrismMesh::build`]), which lets a hinted query
    /// skip the descent. Computed once, on first use: O(F log F), parallel
    /// unless first reached from a rayon worker; 16 bytes per triangle.
    pub(crate) fn prisms(&self) -> &crate::spatial::Prisms {
        self.prisms
            .get_or_init(|| self.prism_mesh().build(on_rayon_worker()))
    }

    /// The grid's process-unique id (a clone keeps its original's). O(1).
    pub(crate) fn id(&self) -> u64 {
        self.id
    }

    /// Bounding box of the vertices.
    pub fn bbox(&self) -> Aabb {
        self.bbox
    }
    /// Distance below which two bodies are in contact:
    /// [`CONTACT_FRACTION`] of the bounding-box diagonal. O(1).
    pub fn contact_gap(&self) -> f64 {
        self.bbox.diagonal() * CONTACT_FRACTION
    }
    /// What was found and repaired on input.
    pub fn report(&self) -> &ValidationReport {
        &self.report
    }
}

/// `(a + b + c) / 3` per coordinate: [`Grid::centroid`]'s formula, in one place.
#[inline]
fn centroid3([a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
}

/// True on a rayon worker thread. A lazy initialisation ([`Grid::contact_faces`],
/// [`Grid::contact_lists`]) first reached from parallel work (batch queries,
/// the simplifier's estimates) must not fork parallel work of its own: while
/// waiting for it, the worker may run another of the caller's jobs, which
/// reaches the same initialisation again on the same thread, and a
/// `OnceLock` initialised reentrantly deadlocks. There it runs sequentially
/// (the same result: each entry is computed on its own); callers that can
/// initialise beforehand, outside the parallel work, do so.
pub(crate) fn on_rayon_worker() -> bool {
    rayon::current_thread_index().is_some()
}

/// Checks a grid's raw arrays: at least one vertex and one triangle, finite
/// coordinates, indices in range, one value per vertex in each point array.
/// O(V + F).
fn check_arrays(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    point_data: &[PointArray],
) -> Result<()> {
    if vertices.is_empty() || triangles.is_empty() {
        return Err(Error::Empty(format!(
            "{} vertices and {} triangles given",
            vertices.len(),
            triangles.len()
        )));
    }
    validate::check_input(vertices, triangles)?;
    if let Some(a) = point_data.iter().find(|a| a.values.len() != vertices.len()) {
        return Err(Error::InvalidArgument(format!(
            "array '{}' has {} values for {} vertices",
            a.name,
            a.values.len(),
            vertices.len()
        )));
    }
    Ok(())
}

/// Checks that `sizes` has `n` values, each finite and > 0.
pub(crate) fn check_sizes(sizes: &[f64], n: usize) -> Result<()> {
    if sizes.len() != n {
        return Err(Error::InvalidArgument(format!(
            "{} sizes given for {n} vertices",
            sizes.len()
        )));
    }
    if let Some(i) = sizes.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
        return Err(Error::InvalidSize(format!(
            "size of vertex {i} is {} (must be finite and > 0)",
            sizes[i]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn builds_and_reports() {
        let (v, t) = square();
        let g = Grid::from_arrays(v, t, Some(vec![1.0; 4]), &BuildOptions::default()).unwrap();
        assert_eq!(g.report().boundary_edges, 4);
        assert_eq!(g.report().bodies, 1);
        assert_eq!(g.report().open_bodies, 1);
        assert_eq!(g.topology().edges.len(), 5);
        assert_eq!(g.sizes().unwrap().len(), 4);
    }

    #[test]
    fn rejects_bad_input() {
        let (v, t) = square();
        let o = BuildOptions::default();
        assert!(matches!(
            Grid::from_arrays(v.clone(), vec![[0, 1, 7]], None, &o),
            Err(Error::OutOfRange(_))
        ));
        let mut bad = v.clone();
        bad[2][1] = f64::NAN;
        assert!(matches!(
            Grid::from_arrays(bad, t.clone(), None, &o),
            Err(Error::NonFinite(_))
        ));
        assert!(matches!(
            Grid::from_arrays(v.clone(), t.clone(), Some(vec![1.0, 0.0, 1.0, 1.0]), &o),
            Err(Error::InvalidSize(_))
        ));
        assert!(matches!(
            Grid::from_arrays(v.clone(), t.clone(), Some(vec![1.0; 3]), &o),
            Err(Error::InvalidArgument(_))
        ));
        assert!(matches!(
            Grid::from_arrays(v.clone(), vec![], None, &o),
            Err(Error::Empty(_))
        ));
        // Finite but beyond MAX_COORDINATE: squared distances would overflow.
        let mut huge = v.clone();
        huge[1][0] = 1e200;
        assert!(matches!(
            Grid::from_arrays(huge, t.clone(), None, &o),
            Err(Error::NonFinite(_))
        ));
        let line = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(matches!(
            Grid::from_arrays(line, vec![[0, 1, 2]], None, &o),
            Err(Error::Empty(_))
        ));
    }

    #[test]
    fn welds_soups_and_keeps_sizes() {
        // Two triangles of a square as a soup.
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [3, 4, 5]];
        let s = vec![1.0, 2.0, 3.0, 1.0, 3.0, 4.0];
        let o = BuildOptions::for_format(Format::Stl);
        let g = Grid::from_arrays(v, t, Some(s), &o).unwrap();
        assert_eq!(g.vertices().len(), 4);
        assert_eq!(g.report().welded_vertices, 2);
        assert_eq!(g.sizes().unwrap(), &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(g.report().boundary_edges, 4);
    }
}
