use abgs::Grid;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let g = Grid::load(std::path::Path::new(&p)).unwrap();
    let c: Vec<f64> = std::env::args().nth(2).unwrap().split(',').map(|s| s.parse().unwrap()).collect();
    let q = [c[0], c[1], c[2]];
    let v = g.vertices();
    let f = abgs::mesh::Features::detect(&g, 30.0);
    let topo = g.topology();
    for (i, t) in g.triangles().iter().enumerate() {
        let cp = abgs::geometry::closest_point_triangle(q, v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        if cp.dist2.sqrt() < c[3] {
            let n = abgs::geometry::triangle_normal2(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let l = abgs::geometry::norm(n);
            let fe: Vec<(u8, usize)> = topo.face_edges[i].iter().map(|&e| (f.edge_flags[e as usize], topo.faces_of_edge(e as usize).len())).collect();
            println!("f{i} body {} patch {} d {:.4} n {:.3?} area {:.3e} edges {:?} {:?} {:?}", topo.face_body[i], f.face_patch[i], cp.dist2.sqrt(), abgs::geometry::scale(n, 1.0/l), l/2.0, fe, t, t.map(|x| v[x as usize]));
        }
    }
}
