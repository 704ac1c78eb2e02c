//! `abgs bench-query`: queries per second for plain, hinted and batch queries on
//! three point sets, with one thread and with all threads.

use crate::points::standard_sets;
use abgs::{Error, Result};
use rayon::prelude::*;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Best rate (items per second) over three runs, each repeating `f` until it
/// has taken at least `secs`.
fn rate(n: usize, secs: f64, mut f: impl FnMut() -> f64) -> (f64, f64) {
    let mut best = 0.0f64;
    let mut check = 0.0;
    for _ in 0..3 {
        let t0 = Instant::now();
        let mut reps = 0usize;
        loop {
            check = f();
            reps += 1;
            let el = t0.elapsed().as_secs_f64();
            if el >= secs {
                best = best.max((reps * n) as f64 / el);
                break;
            }
        }
    }
    (best, check)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// Runs the benchmark on `path`.
pub fn run(path: &Path, n: usize, secs: f64, as_json: bool) -> Result<()> {
    if n == 0 {
        return Err(Error::InvalidArgument("--points must be > 0".into()));
    }
    let mut g = crate::progress::load(path)?;
    let field = if g.sizes().is_none() {
        let b = g.bbox();
        let d = b.diagonal();
        let s = g
            .vertices()
            .iter()
            .map(|p| {
                0.01 * d
                    + 0.1 * (p[0] - b.min[0])
                    + 0.08 * (p[1] - b.min[1])
                    + 0.05 * (p[2] - b.min[2])
            })
            .collect();
        g.set_sizes(s)?;
        "linear test field with |grad h| = 0.138 < ln 1.2 (the file has no sizes)"
    } else {
        "from the file"
    };
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let pb = crate::progress::spinner("generating point sets");
    let sets = standard_sets(&g, n);
    pb.finish_and_clear();
    let mut rows = Vec::new();
    for set in &sets {
        let pts = &set.points;
        let mut out = vec![0.0; pts.len()];
        let pb = crate::progress::spinner(format!("measuring {}", set.name));
        let mut row = Vec::new();
        for &threads in &[1usize, all] {
            let tp = pool(threads);
            let plain = tp.install(|| {
                rate(pts.len(), secs, || {
                    pts.par_iter()
                        .with_min_len(1024)
                        .map(|p| g.query_size(*p).unwrap_or(f64::NAN))
                        .sum()
                })
            });
            let hinted = tp.install(|| {
                rate(pts.len(), secs, || {
                    pts.par_chunks(4096)
                        .map(|c| {
                            let mut h = u32::MAX;
                            c.iter()
                                .map(|p| g.query_size_hinted(*p, &mut h).unwrap_or(f64::NAN))
                                .sum::<f64>()
                        })
                        .sum()
                })
            });
            let batch = tp.install(|| {
                rate(pts.len(), secs, || {
                    g.query_sizes(pts, &mut out)
                        .map_or(f64::NAN, |_| out.iter().sum())
                })
            });
            let vol_n = pts.len().min(20_000);
            let volume = tp.install(|| {
                rate(vol_n, secs, || {
                    pts[..vol_n]
                        .par_iter()
                        .with_min_len(256)
                        .map(|p| g.query_volume(*p, 1.2).map_or(f64::NAN, |h| h.size))
                        .sum()
                })
            });
            let mut vol_out = vec![0.0; vol_n];
            let volume_batch = tp.install(|| {
                rate(vol_n, secs, || {
                    g.query_sizes_volume(&pts[..vol_n], 1.2, &mut vol_out)
                        .map_or(f64::NAN, |_| vol_out.iter().sum())
                })
            });
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs();
            let agree = close(plain.1, hinted.1)
                && close(plain.1, batch.1)
                && close(volume.1, volume_batch.1);
            row.push((
                threads,
                plain.0,
                hinted.0,
                batch.0,
                volume.0,
                volume_batch.0,
                agree,
            ));
        }
        pb.finish_and_clear();
        rows.push((set.name, row));
    }
    let st = g.stats();
    let bpt = st.query_bytes_per_triangle(&g);
    if as_json {
        let v = json!({
            "grid": path.display().to_string(), "triangles": st.triangles, "vertices": st.vertices,
            "sizes": field, "points_per_set": n, "query_bytes_per_triangle": bpt,
            "results": rows.iter().map(|(name, r)| json!({
                "set": name,
                "runs": r.iter().map(|(t, p, h, b, vol, vb, ok)| json!({
                    "threads": t, "plain_qps": p, "hinted_qps": h, "batch_qps": b, "volume_qps": vol,
                    "volume_batch_qps": vb, "answers_agree": ok
                })).collect::<Vec<_>>()
            })).collect::<Vec<_>>()
        });
        println!("{}", serde_json::to_string_pretty(&v).expect("json"));
        return Ok(());
    }
    println!(
        "grid {}: {} triangles, {} vertices; sizes {}; {:.1} bytes/triangle (grid+BVH); {} points per set",
        path.display(),
        st.triangles,
        st.vertices,
        field,
        bpt,
        n
    );
    println!(
        "{:<13} {:>7} {:>14} {:>14} {:>14} {:>14} {:>14}  answers",
        "point set",
        "threads",
        "plain q/s",
        "hinted q/s",
        "batch q/s",
        "volume q/s",
        "vol. batch q/s"
    );
    for (name, r) in &rows {
        for (t, p, h, b, vol, vb, ok) in r {
            println!(
                "{:<13} {:>7} {:>14.0} {:>14.0} {:>14.0} {:>14.0} {:>14.0}  {}",
                name,
                t,
                p,
                h,
                b,
                vol,
                vb,
                if *ok { "identical" } else { "DIFFER" }
            );
        }
    }
    Ok(())
}
