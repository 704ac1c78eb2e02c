//! A grid put back together from stored parts ([`crate::io::abgs_bin`]):
//! checked as [`Grid::from_arrays`] checks its input, but neither welded nor
//! re-oriented (the parts are a grid already, kept bit for bit), with the
//! stored BVH layout checked and used instead of a new build.
//!
//! Nothing in the parts is trusted: coordinates must be finite and within
//! [`crate::geometry::MAX_COORDINATE`], indices in range, sizes finite and
//! positive, the extent within [`super::EXTENT_RANGE`], and no triangle may be
//! degenerate (a built grid never keeps one: the zero-area test does not
//! depend on the corner order, so re-orienting cannot make one). The
//! adjacency is rebuilt. The input history must agree with the counts.

use super::topology::Topology;
use super::{check_arrays, check_extent, check_sizes, validate, Checked, Grid, ValidationReport};
use crate::error::{Error, Result};
use crate::geometry::Aabb;
use crate::io::PointArray;
use crate::spatial::{Bvh, BvhLayout};

/// What a grid's input was, as its [`ValidationReport`] records it: the
/// counts that cannot be recomputed from the grid itself.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InputHistory {
    /// Vertices given ([`ValidationReport::input_vertices`]).
    pub input_vertices: u64,
    /// Triangles given ([`ValidationReport::input_triangles`]).
    pub input_triangles: u64,
    /// Vertices merged by welding.
    pub welded_vertices: u64,
    /// Triangles dropped for a repeated corner.
    pub dropped_repeated_index: u64,
    /// Triangles dropped for zero area.
    pub dropped_zero_area: u64,
    /// Triangles re-oriented.
    pub flipped_triangles: u64,
    /// Bodies that could not be oriented consistently.
    pub non_orientable_bodies: u64,
}

impl InputHistory {
    /// The history recorded in `report`.
    pub fn of(report: &ValidationReport) -> InputHistory {
        InputHistory {
            input_vertices: report.input_vertices as u64,
            input_triangles: report.input_triangles as u64,
            welded_vertices: report.welded_vertices as u64,
            dropped_repeated_index: report.dropped_repeated_index as u64,
            dropped_zero_area: report.dropped_zero_area as u64,
            flipped_triangles: report.flipped_triangles as u64,
            non_orientable_bodies: report.non_orientable_bodies as u64,
        }
    }

    /// The history as a report (derived counts zero), after checking that it
    /// agrees with a grid of `nv` vertices and `nt` triangles: input vertices
    /// = kept + welded, input triangles = kept + dropped, at most `nt` flipped.
    fn to_report(self, nv: usize, nt: usize) -> Result<ValidationReport> {
        let bad = |what: String| Err(Error::InvalidArgument(format!("input history: {what}")));
        let h = self;
        if Some(h.input_vertices) != (nv as u64).checked_add(h.welded_vertices) {
            return bad(format!(
                "{} input vertices, but {nv} kept and {} welded",
                h.input_vertices, h.welded_vertices
            ));
        }
        let dropped = h.dropped_repeated_index.checked_add(h.dropped_zero_area);
        if Some(h.input_triangles) != dropped.and_then(|d| d.checked_add(nt as u64)) {
            return bad(format!(
                "{} input triangles, but {nt} kept and {} + {} dropped",
                h.input_triangles, h.dropped_repeated_index, h.dropped_zero_area
            ));
        }
        if h.flipped_triangles > nt as u64 {
            return bad(format!("{} of {nt} triangles flipped", h.flipped_triangles));
        }
        let n = |x: u64| {
            usize::try_from(x)
                .map_err(|_| Error::InvalidArgument(format!("input history: {x} too large")))
        };
        Ok(ValidationReport {
            input_vertices: n(h.input_vertices)?,
            input_triangles: n(h.input_triangles)?,
            welded_vertices: n(h.welded_vertices)?,
            dropped_repeated_index: n(h.dropped_repeated_index)?,
            dropped_zero_area: n(h.dropped_zero_area)?,
            flipped_triangles: n(h.flipped_triangles)?,
            non_orientable_bodies: n(h.non_orientable_bodies)?,
            ..Default::default()
        })
    }
}

/// The stored form of a grid: its arrays, its input history and, optionally,
/// the layout of its hierarchy. Plain data, not yet checked.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GridParts {
    /// Vertex coordinates.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles (vertex indices).
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex sizes, if any.
    pub sizes: Option<Vec<f64>>,
    /// Other per-vertex arrays.
    pub arrays: Vec<PointArray>,
    /// What the grid's input was.
    pub history: InputHistory,
    /// The hierarchy's layout; `None` builds it anew.
    pub bvh: Option<BvhLayout>,
}

impl Grid {
    /// The parts that give this grid back through [`Grid::from_parts`]
    /// (copies), the hierarchy's layout included when `with_bvh`. O(V + F).
    pub fn to_parts(&self, with_bvh: bool) -> GridParts {
        GridParts {
            vertices: self.vertices.clone(),
            triangles: self.triangles.clone(),
            sizes: self.sizes.clone(),
            arrays: self.extra.clone(),
            history: InputHistory::of(&self.report),
            bvh: with_bvh.then(|| self.bvh.layout()),
        }
    }

    /// The grid whose parts these are ([`Grid::to_parts`]), checked as
    /// described in the module documentation: the same vertices, triangles,
    /// sizes and arrays, bit for bit, and the same answers to every query.
    /// With a layout, the hierarchy is checked and taken from it (O(F));
    /// without, it is built (O(F log F)). The adjacency is rebuilt
    /// (O(F log F)).
    ///
    /// Errors: [`Error::Empty`], [`Error::NonFinite`], [`Error::OutOfRange`],
    /// [`Error::InvalidSize`] as [`Grid::from_arrays`]; [`Error::InvalidArgument`]
    /// for a degenerate triangle, an array of the wrong length, a history
    /// that disagrees with the counts, or a hierarchy layout that is not one
    /// over these triangles.
    pub fn from_parts(parts: GridParts) -> Result<Grid> {
        let GridParts {
            vertices,
            triangles,
            sizes,
            arrays,
            history,
            bvh,
        } = parts;
        check_arrays(&vertices, &triangles, &arrays)?;
        if let Some(s) = &sizes {
            check_sizes(s, vertices.len())?;
        }
        check_extent(&Aabb::from_points(&vertices))?;
        let (_, repeated, zero) = validate::drop_degenerate(&vertices, &triangles);
        if repeated + zero > 0 {
            let f = triangles
                .iter()
                .position(|t| validate::drop_degenerate(&vertices, &[*t]).0.is_empty())
                .unwrap_or(0);
            return Err(Error::InvalidArgument(format!(
                "triangle {f} {:?} is degenerate (a repeated corner or zero area; {} in all), \
                 which a grid never keeps",
                triangles[f],
                repeated + zero
            )));
        }
        let report = history.to_report(vertices.len(), triangles.len())?;
        // The adjacency and the hierarchy are independent: side by side.
        let (topology, bvh) = rayon::join(
            || Topology::build(vertices.len(), &triangles),
            || match bvh {
                Some(layout) => Bvh::from_layout(&vertices, &triangles, layout)
                    .map_err(|e| Error::InvalidArgument(format!("BVH layout: {e}"))),
                None => Ok(Bvh::build(&vertices, &triangles)),
            },
        );
        let bvh = bvh?;
        if report.non_orientable_bodies > topology.body_count as usize {
            return Err(Error::InvalidArgument(format!(
                "input history: {} non-orientable bodies of {}",
                report.non_orientable_bodies, topology.body_count
            )));
        }
        Ok(Grid::assemble(
            Checked {
                vertices,
                triangles,
                sizes,
                extra: arrays,
            },
            topology,
            bvh,
            report,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildOptions;

    /// A welded soup with one degenerate triangle (dropped), one triangle
    /// facing the other way (flipped), an unreferenced vertex and an array.
    fn grid() -> Grid {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
        ];
        let t = vec![[0, 1, 2], [3, 4, 5], [0, 2, 6]];
        let s = vec![0.1, 0.2, 0.3, 0.1, 0.4, 0.3, 0.5];
        let o = BuildOptions {
            weld_relative_tolerance: Some(1e-9),
            orient: true,
        };
        let mut g = Grid::from_arrays(v, t, Some(s), &o).unwrap();
        g.set_point_array("h0", vec![1.0, 2.0, 3.0, 4.0, 5.0])
            .unwrap();
        g
    }

    #[test]
    fn parts_give_the_same_grid_back() {
        let g = grid();
        assert_eq!(g.report().welded_vertices, 2);
        assert_eq!(g.report().dropped_zero_area, 1);
        assert_eq!(g.report().flipped_triangles, 1);
        for with_bvh in [true, false] {
            let r = Grid::from_parts(g.to_parts(with_bvh)).unwrap();
            assert_eq!(r.vertices(), g.vertices());
            assert_eq!(r.triangles(), g.triangles());
            assert_eq!(r.sizes(), g.sizes());
            assert_eq!(r.point_arrays(), g.point_arrays());
            assert_eq!(r.report(), g.report());
            assert_eq!(r.bvh().layout(), g.bvh().layout());
            assert_eq!(r.node_min_size(), g.node_min_size());
            assert_eq!(r.to_parts(true), g.to_parts(true));
        }
    }

    #[test]
    fn broken_parts_are_refused() {
        let g = grid();
        type Edit = Box<dyn Fn(&mut GridParts)>;
        let cases: Vec<(&str, Edit)> = vec![
            ("NaN", Box::new(|p| p.vertices[1][2] = f64::NAN)),
            ("index", Box::new(|p| p.triangles[0][1] = 99)),
            ("size", Box::new(|p| p.sizes.as_mut().unwrap()[0] = 0.0)),
            (
                "size count",
                Box::new(|p| {
                    p.sizes.as_mut().unwrap().pop();
                }),
            ),
            (
                "array length",
                Box::new(|p| {
                    p.arrays[0].values.pop();
                }),
            ),
            (
                "repeated corner",
                Box::new(|p| p.triangles[0][1] = p.triangles[0][0]),
            ),
            ("zero area", Box::new(|p| p.vertices[2] = [0.5, 0.0, 0.0])),
            ("history", Box::new(|p| p.history.welded_vertices += 1)),
            (
                "history drops",
                Box::new(|p| p.history.dropped_zero_area = u64::MAX),
            ),
            (
                "history flips",
                Box::new(|p| p.history.flipped_triangles = 3),
            ),
            (
                "history bodies",
                Box::new(|p| p.history.non_orientable_bodies = 2),
            ),
            ("no triangles", Box::new(|p| p.triangles.clear())),
            (
                "extent",
                Box::new(|p| p.vertices.iter_mut().flatten().for_each(|c| *c *= 1e-80)),
            ),
            (
                "bvh slots",
                Box::new(|p| {
                    p.bvh.as_mut().unwrap().prim_triangle.pop();
                }),
            ),
        ];
        for (what, f) in &cases {
            let mut p = g.to_parts(true);
            f(&mut p);
            assert!(Grid::from_parts(p).is_err(), "{what}");
        }
    }

    /// Any layout that passes the checks gives right answers: the boxes are
    /// computed, never read. Here two primitive slots trade triangles.
    #[test]
    fn a_permuted_layout_answers_the_same() {
        let g = grid();
        let mut p = g.to_parts(true);
        p.bvh.as_mut().unwrap().prim_triangle.swap(0, 1);
        let r = Grid::from_parts(p).unwrap();
        assert_ne!(r.bvh().layout(), g.bvh().layout());
        for q in [
            [0.3, 0.2, 1.0],
            [0.9, 0.1, -0.5],
            [5.0, 5.0, 5.0],
            [0.5, 0.5, 0.0],
        ] {
            assert_eq!(r.closest(q, None).unwrap(), g.closest(q, None).unwrap());
            assert_eq!(
                r.query_volume(q, 1.2).unwrap(),
                g.query_volume(q, 1.2).unwrap()
            );
        }
    }
}
