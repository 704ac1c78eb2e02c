use abgs::remesh::{remesh, RemeshParams};
use abgs::mesh::Features;
use abgs::Grid;
fn segs(g: &Grid, f: &Features) -> Vec<([[f64;3];2], f64)> {
    let v = g.vertices(); let t = g.topology();
    let n = abgs::mesh::features::face_normals(v, g.triangles());
    (0..t.edges.len()).filter(|&e| f.edge_flags[e] != 0).map(|e| {
        let fs = t.faces_of_edge(e);
        let ang = if fs.len() == 2 { abgs::geometry::dot(n[fs[0] as usize], n[fs[1] as usize]).clamp(-1.0,1.0).acos().to_degrees() } else { -1.0 };
        (t.edges[e].map(|i| v[i as usize]), ang)
    }).collect()
}
fn dist(p: [f64;3], s: &[([[f64;3];2], f64)]) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    for (q, a) in s { let t = abgs::geometry::closest_point_on_segment(p, q[0], q[1]); let d = abgs::geometry::dist2(p, abgs::geometry::lerp(q[0], q[1], t)).sqrt(); if d < best.0 { best = (d, *a); } }
    best
}
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let g = Grid::load(std::path::Path::new(&p)).unwrap();
    let out = remesh(&g, &RemeshParams::default()).unwrap();
    let diag = g.bbox().diagonal();
    let fi = Features::detect(&g, 30.0); let fo = Features::detect(&out.grid, 30.0);
    let si = segs(&g, &fi); let so: Vec<([[f64;3];2], f64)> = if std::env::var_os("TRACKED").is_some() { out.feature_edges.iter().map(|e| (e.map(|i| out.grid.vertices()[i as usize]), 0.0)).collect() } else { segs(&out.grid, &fo) };
    println!("input feature edges {} output {}", si.len(), so.len());
    for lo in [15.0, 20.0, 25.0] {
        let si_lo = segs(&g, &Features::detect(&g, lo)); let so_lo = segs(&out.grid, &Features::detect(&out.grid, lo));
        let a = si.iter().map(|(s, _)| { let m = abgs::geometry::lerp(s[0], s[1], 0.5); dist(m, &so_lo).0 / diag }).fold(0.0, f64::max);
        let b = so.iter().map(|(s, _)| { let m = abgs::geometry::lerp(s[0], s[1], 0.5); dist(m, &si_lo).0 / diag }).fold(0.0, f64::max);
        println!("hysteresis {lo}: in->out {a:.2e} out->in {b:.2e}");
    }
    let mut worst_in: Vec<(f64, f64, f64, [f64;3])> = si.iter().map(|(s, a)| { let m = abgs::geometry::lerp(s[0], s[1], 0.5); let (d, _) = dist(m, &so); (d / diag, *a, 0.0, m) }).collect();
    worst_in.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
    println!("input->output: far input features (d/diag, input dihedral):");
    for w in worst_in.iter().take(8) { println!("  {:.2e} {:.1} at {:?}", w.0, w.1, w.3); }
    println!("  count > 1e-3: {}", worst_in.iter().filter(|w| w.0 > 1e-3).count());
    let mut worst_out: Vec<(f64, f64, f64, [f64;3])> = so.iter().map(|(s, a)| { let m = abgs::geometry::lerp(s[0], s[1], 0.5); let (d, _) = dist(m, &si); (d / diag, *a, 0.0, m) }).collect();
    worst_out.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
    println!("output->input: far output features (d/diag, output dihedral):");
    for w in worst_out.iter().take(8) { println!("  {:.2e} {:.1} at {:?}", w.0, w.1, w.3); }
    println!("  count > 1e-3: {}", worst_out.iter().filter(|w| w.0 > 1e-3).count());
    if let Ok(x) = std::env::var("AT") {
        let c: Vec<f64> = x.split(',').map(|s| s.parse().unwrap()).collect();
        let p = [c[0], c[1], c[2]];
        println!("input feature segs near:");
        for (s, a) in &si { let t = abgs::geometry::closest_point_on_segment(p, s[0], s[1]); if abgs::geometry::dist2(p, abgs::geometry::lerp(s[0], s[1], t)).sqrt() < c[3] { println!("  {:.3?} {:.1}", s, a); } }
        println!("output feature segs near:");
        for (s, a) in &so { let t = abgs::geometry::closest_point_on_segment(p, s[0], s[1]); if abgs::geometry::dist2(p, abgs::geometry::lerp(s[0], s[1], t)).sqrt() < c[3] { println!("  {:.3?} {:.1}", s, a); } }
    }
    if std::env::var_os("AROUND").is_some() {
        let w = worst_out[0].3; let l = out.report.target_range[0];
        println!("output around {w:?} (r {l})"); around(&out.grid, w, 2.0 * l);
        println!("input around:"); around(&g, w, 4.0 * l);
    }
}
#[allow(dead_code)]
fn around(g: &Grid, p: [f64;3], r: f64) {
    let v = g.vertices();
    for (i, t) in g.triangles().iter().enumerate() {
        let c = abgs::geometry::lerp(v[t[0] as usize], abgs::geometry::lerp(v[t[1] as usize], v[t[2] as usize], 0.5), 2.0/3.0);
        if abgs::geometry::dist2(c, p).sqrt() < r {
            let n = abgs::geometry::triangle_normal2(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let l = abgs::geometry::norm(n);
            println!("  f{i} {:?} n {:?} angles {:?}", t, abgs::geometry::scale(n, 1.0/l), abgs::geometry::triangle_angles_deg(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]));
        }
    }
}
