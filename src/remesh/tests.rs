use super::*;
use crate::mesh::halfedge::HalfedgeMesh;

fn cube(n: usize) -> Grid {
    // Unit cube, each face an n × n grid.
    let mut v = Vec::new();
    let mut t = Vec::new();
    let faces: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    for (o, u, w) in faces {
        let base = v.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                v.push([0, 1, 2].map(|k| o[k] + a * u[k] + b * w[k]));
            }
        }
        let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    Grid::from_arrays(v, t, None, &BuildOptions { weld_relative_tolerance: Some(1e-9), orient: true }).unwrap()
}

#[test]
fn split_pass_terminates() {
    let g = cube(1);
    let f = Features::detect(&g, 30.0);
    let (mut m, _) = HalfedgeMesh::from_grid(&g, Some(&f));
    for v in 0..m.n_vertices() {
        m.vertex_size[v] = 0.2;
    }
    let area = |m: &HalfedgeMesh| m.faces().map(|f| 0.5 * crate::geometry::norm(m.face_normal2(f))).sum::<f64>();
    let n = ops::split_long(&mut m);
    m.check().unwrap();
    eprintln!("area {}", area(&m));
    let mut pos: Vec<_> = m.vertices().map(|v| m.positions[v as usize]).collect();
    pos.sort_by(|a, b| a.partial_cmp(b).unwrap());
    pos.dedup();
    eprintln!("distinct {} of {}", pos.len(), m.vertex_count());
    eprintln!("{n} splits, {} faces", m.face_count());
    assert!(n < 10_000);
}
