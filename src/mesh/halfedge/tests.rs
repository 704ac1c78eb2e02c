use super::*;
use crate::mesh::{BuildOptions, Features, Grid, Topology};

fn grid(v: Vec<[f64; 3]>, t: Vec<[u32; 3]>) -> Grid {
    Grid::from_arrays(v, t, None, &BuildOptions::default()).unwrap()
}

/// An n × n grid of squares in z = 0, two triangles each.
fn plate(n: usize) -> Grid {
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            v.push([i as f64, j as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    grid(v, t)
}

fn cube() -> Grid {
    let (v, t) = crate::mesh::validate::tests::cube();
    grid(v, t)
}

#[test]
fn builds_closed_and_open() {
    let g = cube();
    let (m, r) = HalfedgeMesh::from_grid(&g, None);
    m.check().unwrap();
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (8, 18, 12)
    );
    assert_eq!(r.split_vertices + r.detached_faces + r.locked_edges, 0);
    assert!(m
        .vertices()
        .all(|v| !m.is_boundary_vertex(v) && m.valence(v) >= 3));

    let g = plate(3);
    let f = Features::detect(&g, 30.0);
    let (m, _) = HalfedgeMesh::from_grid(&g, Some(&f));
    m.check().unwrap();
    let boundary = m.edges().filter(|&e| m.is_boundary_edge(e)).count();
    assert_eq!(boundary, 12);
    assert!(m
        .edges()
        .all(|e| m.is_boundary_edge(e) == (m.edge_flags[e as usize] & E_FEATURE != 0)));
    // The four plate corners have boundary valence 2 but two feature edges; the
    // others on the rim are feature vertices, inner ones are free.
    let nfeat = m
        .vertices()
        .filter(|&v| m.vertex_flags[v as usize] & V_FEATURE != 0)
        .count();
    assert_eq!(nfeat, 12);
}

#[test]
fn split_collapse_flip_compact() {
    let g = plate(4);
    let (mut m, _) = HalfedgeMesh::from_grid(&g, None);
    let (v0, e0, f0) = (m.vertex_count(), m.edge_count(), m.face_count());
    // Split an interior and a boundary edge.
    let inner = m.edges().find(|&e| !m.is_boundary_edge(e)).unwrap();
    let [a, b] = m.edge_vertices(inner);
    let mid = crate::geometry::lerp(m.positions[a as usize], m.positions[b as usize], 0.5);
    let v = m.split(inner, mid);
    m.check().unwrap();
    assert_eq!(m.valence(v), 4);
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (v0 + 1, e0 + 3, f0 + 2)
    );
    let bnd = m.edges().find(|&e| m.is_boundary_edge(e)).unwrap();
    let [a, b] = m.edge_vertices(bnd);
    let mid = crate::geometry::lerp(m.positions[a as usize], m.positions[b as usize], 0.5);
    let w = m.split(bnd, mid);
    m.check().unwrap();
    assert!(m.is_boundary_vertex(w));
    assert_eq!(m.valence(w), 3);
    // Collapse the new interior vertex back.
    let h = m.outgoing(v).next().unwrap();
    assert!(m.can_collapse(h));
    let target = m.positions[m.to_vertex(h) as usize];
    m.collapse(h, target).unwrap();
    m.check().unwrap();
    assert!(m.vertex_deleted(v));
    // Collapse the boundary vertex along the boundary.
    let hb = m
        .outgoing(w)
        .find(|&h| m.is_boundary_edge(m.edge(h)))
        .unwrap();
    assert!(m.can_collapse(hb));
    let t = m.positions[m.to_vertex(hb) as usize];
    m.collapse(hb, t).unwrap();
    m.check().unwrap();
    assert_eq!((m.vertex_count(), m.face_count()), (v0, f0));
    // Flip every flippable interior edge once.
    let mut flips = 0;
    for e in m.edges().collect::<Vec<_>>() {
        if m.is_flip_ok(e) {
            m.flip(e).unwrap();
            m.check().unwrap();
            flips += 1;
        }
    }
    assert!(flips > 10);
    let (bv, bt, _) = m.to_arrays(true);
    let live: Vec<[f64; 3]> = m.vertices().map(|v| m.positions[v as usize]).collect();
    let map = m.compact();
    m.check().unwrap();
    // In place, in order: the same mesh, the same numbering, no spare room.
    let (av, at, _) = m.to_arrays(true);
    assert_eq!((av, at), (bv, bt));
    assert_eq!(m.positions, live);
    assert_eq!(m.positions.capacity(), m.positions.len());
    assert_eq!(map.iter().filter(|&&x| x != NONE).count(), v0);
    assert_eq!(m.n_vertices(), v0);
    let (v, t, _) = m.to_arrays(true);
    let topo = Topology::build(v.len(), &t);
    assert_eq!(topo.boundary_edge_count(), 16);
    assert_eq!(topo.non_manifold_edge_count(), 0);
}

#[test]
fn rank_counts_the_kept_slots_before() {
    for n in [0usize, 1, 63, 64, 65, 200] {
        let del: Vec<bool> = (0..n).map(|i| (i * 7 + i / 5) % 3 == 0).collect();
        let r = super::Rank::new(&del);
        let mut kept = 0;
        for (i, &d) in del.iter().enumerate() {
            assert_eq!(r.get(i), kept, "slot {i} of {n}");
            kept += u32::from(!d);
        }
    }
}

#[test]
fn reserved_splits_fit_without_growing() {
    let g = plate(4);
    let (mut m, _) = HalfedgeMesh::from_grid(&g, None);
    let edges: Vec<u32> = m.edges().collect();
    m.reserve_splits(edges.len());
    let cap = (m.positions.capacity(), m.to.capacity(), m.fhe.capacity());
    assert!(cap.0 >= m.n_vertices() + edges.len());
    for e in edges {
        let [a, b] = m.edge_vertices(e);
        let mid = crate::geometry::lerp(m.positions[a as usize], m.positions[b as usize], 0.5);
        m.split(e, mid);
    }
    m.check().unwrap();
    assert_eq!(
        (m.positions.capacity(), m.to.capacity(), m.fhe.capacity()),
        cap,
        "no array grew past the reservation"
    );
}

#[test]
fn link_condition_rejects() {
    // A tetrahedron: no edge may collapse.
    let g = grid(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    );
    let (mut m, _) = HalfedgeMesh::from_grid(&g, None);
    m.check().unwrap();
    for h in 0..12 {
        assert!(!m.can_collapse(h));
        assert!(m.collapse(h, [0.0; 3]).is_err());
    }
    // Single triangle: nothing collapses or flips.
    let g = grid(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let (m, _) = HalfedgeMesh::from_grid(&g, None);
    assert!((0..6).all(|h| !m.can_collapse(h)));
    assert!((0..3).all(|e| !m.is_flip_ok(e)));
}

#[test]
fn non_manifold_edges_are_split_and_merged_back() {
    // Three fins on edge (0, 1) plus two cubes sharing a vertex.
    let (mut v, mut t) = crate::test_shapes::three_fins(1.0);
    let c = cube();
    let o = v.len() as u32;
    v.extend(c.vertices().iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
    t.extend(c.triangles().iter().map(|x| x.map(|i| i + o)));
    let o2 = v.len() as u32;
    // Second cube touching the first at its corner (4, 1, 1) = vertex o + 7.
    v.extend(
        c.vertices()
            .iter()
            .map(|p| [p[0] + 4.0, p[1] + 1.0, p[2] + 1.0]),
    );
    t.extend(
        c.triangles()
            .iter()
            .map(|x| x.map(|i| if i == 0 { o + 7 } else { i + o2 })),
    );
    let g = grid(v, t);
    let topo: &Topology = g.topology();
    assert_eq!(topo.non_manifold_edge_count(), 1);
    let (m, r) = HalfedgeMesh::from_grid(&g, None);
    m.check().unwrap();
    assert_eq!(r.split_vertices, 3);
    assert!(r.locked_edges >= 1);
    let (v2, t2, _) = m.to_arrays(true);
    let g2 = grid(v2, t2);
    assert_eq!(g2.vertices().len(), g.vertices().len() - 1);
    assert_eq!(g2.topology().non_manifold_edge_count(), 1);
    assert_eq!(g2.topology().body_count, g.topology().body_count);
    assert_eq!(g2.report().boundary_edges, g.report().boundary_edges);
}
