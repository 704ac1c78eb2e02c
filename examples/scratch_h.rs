use abgs::remesh::{remesh, RemeshParams};
use abgs::Grid;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let g = Grid::load(std::path::Path::new(&p)).unwrap();
    let out = remesh(&g, &RemeshParams::default()).unwrap();
    let diag = g.bbox().diagonal();
    for (name, a, b) in [("in->out", &g, &out.grid), ("out->in", &out.grid, &g)] {
        let mut pts: Vec<[f64;3]> = abgs::sampling::surface_points(a, 50000, 7).into_iter().map(|s| s.1).collect();
        pts.extend_from_slice(a.vertices());
        let mut d: Vec<(f64, [f64;3], [f64;3])> = pts.iter().map(|&p| { let h = b.bvh().closest(p, None).unwrap(); (h.closest.dist2.sqrt() / diag, p, h.closest.point) }).collect();
        d.sort_by(|x, y| y.0.partial_cmp(&x.0).unwrap());
        println!("{name}:");
        for x in d.iter().take(5) { println!("  {:.2e} at {:?} -> {:?}", x.0, x.1, x.2); }
    }
    if let Ok(x) = std::env::var("AT") { let c: Vec<f64> = x.split(',').map(|s| s.parse().unwrap()).collect(); println!("input:"); around(&g, [c[0], c[1], c[2]], c[3]); println!("output:"); around(&out.grid, [c[0], c[1], c[2]], c[3]); }
    println!("target range {:?} L0 {}", out.report.target_range, out.report.target_length);
}
#[allow(dead_code)]
pub fn around(g: &Grid, p: [f64;3], r: f64) {
    let v = g.vertices();
    let f = abgs::mesh::Features::detect(g, 30.0);
    for (i, t) in g.triangles().iter().enumerate() {
        let c = abgs::geometry::closest_point_triangle(p, v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        if c.dist2.sqrt() < r {
            let n = abgs::geometry::triangle_normal2(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let l = abgs::geometry::norm(n);
            let fe: Vec<u8> = g.topology().face_edges[i].iter().map(|&e| f.edge_flags[e as usize]).collect();
            println!("  f{i} patch {} d {:.3} n {:.3?} angles {:.1?} edgeflags {:?} {:?}", f.face_patch[i], c.dist2.sqrt(), abgs::geometry::scale(n, 1.0/l), abgs::geometry::triangle_angles_deg(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]), fe, t.map(|x| v[x as usize]));
        }
    }
}
