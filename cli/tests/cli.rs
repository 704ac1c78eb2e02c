//! End-to-end tests of the `abgs` binary.

use std::path::PathBuf;
use std::process::Command;

fn abgs() -> Command {
    Command::new(env!("CARGO_BIN_EXE_abgs"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("abgs-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// Fails with the command's stderr unless it exited with success.
fn assert_ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The unit square subdivided n × n (two triangles per cell) at height `z(x)`.
fn plate_arrays(n: usize, z: impl Fn(f64) -> f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            v.push([x, y, z(x)]);
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
    (v, t)
}

/// A bumpy plate `z = 0.05·sin(k·x)` without sizes, written to `name`.
fn bumpy_plate(name: &str, n: usize, k: f64) -> PathBuf {
    let (v, t) = plate_arrays(n, |x| 0.05 * (k * x).sin());
    let path = tmp(name);
    abgs::Grid::from_arrays(v, t, None, &abgs::BuildOptions::default())
        .unwrap()
        .save(&path)
        .unwrap();
    path
}

/// A small grid with sizes, written as VTK.
fn sized_grid(tag: &str) -> PathBuf {
    let path = tmp(&format!("plate-{tag}.vtk"));
    let v = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let t = vec![[0, 1, 2], [0, 2, 3]];
    let s = v.iter().map(|p| 0.1 + p[0] + 2.0 * p[1]).collect();
    let g = abgs::Grid::from_arrays(v, t, Some(s), &abgs::BuildOptions::default()).unwrap();
    g.save(&path).unwrap();
    path
}

#[test]
fn info_reports_counts_and_defects() {
    let out = abgs()
        .arg("info")
        .arg(sized_grid("info1"))
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["vertices"], 4);
    assert_eq!(v["triangles"], 2);
    assert_eq!(v["boundary_edges"], 4);
    assert_eq!(v["sizes"]["max"], 3.1);
    assert!(v["defects"]
        .as_array()
        .unwrap()
        .iter()
        .any(|d| d.as_str().unwrap().contains("boundary")));
    let text = abgs()
        .arg("info")
        .arg(sized_grid("info2"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&text.stdout).contains("bytes/triangle"));
}

#[test]
fn query_answers_in_order_in_both_modes() {
    let grid = sized_grid("query");
    let pts = tmp("pts.txt"); // only this test uses it
    std::fs::write(&pts, "# x y z\n0.5 0.25 0\n\n1,1,1\n0 0 -2\n").unwrap();
    let out = abgs()
        .args(["query"])
        .arg(&grid)
        .arg("--points")
        .arg(&pts)
        .output()
        .unwrap();
    assert_ok(&out);
    let vals: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    let expect = [0.1 + 0.5 + 0.5, 0.1 + 1.0 + 2.0, 0.1];
    assert_eq!(vals.len(), 3);
    for (a, b) in vals.iter().zip(expect) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    let out = abgs()
        .args(["query"])
        .arg(&grid)
        .arg("--points")
        .arg(&pts)
        .args(["--mode", "volume", "--beta", "1.5"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let vol: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    // The corner (0,0,-2) is 2 away from the size-0.1 vertex: H <= 0.1 + ln(1.5)·2.
    assert!(vol[2] <= 0.1 + 1.5f64.ln() * 2.0 + 1e-12 && vol[2] > 0.1);
}

#[test]
fn convert_round_trips_sizes() {
    let grid = sized_grid("convert");
    for ext in ["msh", "vtu", "ply", "mesh", "abgs"] {
        let out_path = tmp(&format!("conv.{ext}"));
        let st = abgs()
            .arg("convert")
            .arg(&grid)
            .arg(&out_path)
            .status()
            .unwrap();
        assert!(st.success());
        let g = abgs::Grid::load(&out_path).unwrap();
        assert_eq!(
            g.sizes().unwrap(),
            abgs::Grid::load(&grid).unwrap().sizes().unwrap()
        );
    }
}

#[test]
fn bad_input_fails_with_a_message() {
    let out = abgs()
        .args(["info", "/nonexistent/x.stl"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("abgs: error"));
    let pts = tmp("bad.txt");
    std::fs::write(&pts, "1 2\n").unwrap();
    let out = abgs()
        .arg("query")
        .arg(sized_grid("bad"))
        .arg("--points")
        .arg(&pts)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 1"));
}

#[test]
fn bench_query_runs_and_answers_agree() {
    let out = abgs()
        .arg("bench-query")
        .arg(sized_grid("bench"))
        .args(["--points", "2000", "--seconds", "0.01", "--json"])
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for set in v["results"].as_array().unwrap() {
        for run in set["runs"].as_array().unwrap() {
            assert_eq!(run["answers_agree"], true);
            assert!(run["plain_qps"].as_f64().unwrap() > 0.0);
        }
    }
}

#[test]
fn size_writes_all_arrays_and_check_gradation_passes() {
    // A bumpy plate so that curvature matters.
    let input = bumpy_plate("bumpy.obj", 30, 8.0);
    let out = tmp("bumpy-sized.vtk");
    let st = abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--beta", "1.3", "--source", "point 0.5 0.5 0 0.003 0.05"])
        .output()
        .unwrap();
    assert_ok(&st);
    let g = abgs::Grid::load(&out).unwrap();
    let names: Vec<&str> = g.point_arrays().iter().map(|a| a.name.as_str()).collect();
    for want in ["h0", "h_curv", "h_prox", "lbo"] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    let chk = abgs()
        .arg("check-gradation")
        .arg(&out)
        .args(["--beta", "1.3"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&chk.stdout);
    assert!(chk.status.success(), "{text}");
    assert!(text.contains("faces above 1 + 1e-9:       0"), "{text}");
    assert!(text.contains("h <= h0:                    yes"), "{text}");
    // A steeper bound than the one used must be reported as violated.
    let chk = abgs()
        .arg("check-gradation")
        .arg(&out)
        .args(["--beta", "1.01"])
        .output()
        .unwrap();
    assert!(!chk.status.success());
    // H0 itself (no gradation) violates the bound near the source.
    let raw = tmp("bumpy-raw.vtk");
    assert!(abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&raw)
        .args(["--no-gradation", "--source", "point 0.5 0.5 0 0.003 0.05"])
        .status()
        .unwrap()
        .success());
    let chk = abgs().arg("check-gradation").arg(&raw).output().unwrap();
    assert!(!chk.status.success());
    // Bad parameters fail cleanly.
    let bad = abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--beta", "0.5"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("beta"));
}

/// A closed 1 × 2 × 0.5 box of 12 triangles, written as OBJ.
fn box_obj(tag: &str) -> PathBuf {
    let path = tmp(&format!("box-{tag}.obj"));
    let v = (0..8)
        .map(|i| {
            [
                (i & 1) as f64,
                2.0 * ((i >> 1) & 1) as f64,
                0.5 * ((i >> 2) & 1) as f64,
            ]
        })
        .collect();
    let t = vec![
        [0, 3, 1],
        [0, 2, 3],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    abgs::Grid::from_arrays(v, t, None, &abgs::BuildOptions::default())
        .unwrap()
        .save(&path)
        .unwrap();
    path
}

#[test]
fn grid_remeshes_uniformly_and_by_sizes_and_checks() {
    let input = box_obj("grid");
    let dense = tmp("box-dense.vtk");
    let out = abgs()
        .arg("grid")
        .arg(&input)
        .arg("-o")
        .arg(&dense)
        .args(["--relative", "0.05", "--check"])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("acceptance: pass"), "{stdout}");
    assert!(stdout.contains("min-angle p1:"), "{stdout}");
    assert!(
        stdout.contains("bodies in / out:            1 / 1"),
        "{stdout}"
    );
    assert!(stderr.contains("feature lines 12  corners 8"), "{stderr}");
    assert!(stderr.contains("issues: none"), "{stderr}");
    let g = abgs::Grid::load(&dense).unwrap();
    assert!(g.triangles().len() > 500, "{}", g.triangles().len());
    assert!(g.sizes().is_none());
    // Every vertex lies on the box's surface.
    let hi = [1.0, 2.0, 0.5];
    for p in g.vertices() {
        let inside = (0..3).all(|k| p[k] >= -1e-9 && p[k] <= hi[k] + 1e-9);
        let on_face = (0..3).any(|k| p[k].abs() <= 1e-9 || (p[k] - hi[k]).abs() <= 1e-9);
        assert!(inside && on_face, "{p:?}");
    }

    // Size-driven: sizes from `abgs size`, finer near a point source.
    let sized = tmp("box-sized.vtk");
    let st = abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&sized)
        .args(["--source", "point 0 0 0 0.03 0.3"])
        .output()
        .unwrap();
    assert_ok(&st);
    let dense2 = tmp("box-dense2.vtk");
    let out = abgs()
        .arg("grid")
        .arg(&input)
        .arg("-o")
        .arg(&dense2)
        .arg("--size-from")
        .arg(&sized)
        .arg("--check")
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(stderr.contains("size-driven from"), "{stderr}");
    assert!(stdout.contains("acceptance: pass"), "{stdout}");
    let ratio = stdout
        .lines()
        .find(|l| l.starts_with("edge length / h(midpoint)"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let mean: f64 = ratio
        .split("mean ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{ratio}"));
    assert!((0.85..=1.2).contains(&mean), "{ratio}");
    // Finer near the source corner than at the opposite one.
    let g2 = abgs::Grid::load(&dense2).unwrap();
    let near = |c: [f64; 3]| {
        g2.vertices()
            .iter()
            .filter(|p| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>() < 0.09)
            .count()
    };
    assert!(
        near([0.0; 3]) > 3 * near([1.0, 2.0, 0.5]),
        "{} vs {}",
        near([0.0; 3]),
        near([1.0, 2.0, 0.5])
    );
}

#[test]
fn grid_check_failures_and_bad_arguments_exit_1() {
    // A coarse remesh of a cylinder (no curvature cap) is too far from it.
    let n = 48;
    let mut v = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 2.0]];
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        v.push([a.cos(), a.sin(), 0.0]);
        v.push([a.cos(), a.sin(), 2.0]);
    }
    let (b, tp) = (
        |i: usize| 2 + 2 * (i % n) as u32,
        |i: usize| 3 + 2 * (i % n) as u32,
    );
    let mut t = Vec::new();
    for i in 0..n {
        t.push([b(i), b(i + 1), tp(i + 1)]);
        t.push([b(i), tp(i + 1), tp(i)]);
        t.push([0, b(i + 1), b(i)]);
        t.push([1, tp(i), tp(i + 1)]);
    }
    let input = tmp("cylinder.obj");
    abgs::Grid::from_arrays(v, t, None, &abgs::BuildOptions::default())
        .unwrap()
        .save(&input)
        .unwrap();
    let out_path = tmp("cylinder-dense.vtk");
    let out = abgs()
        .arg("grid")
        .arg(&input)
        .arg("-o")
        .arg(&out_path)
        .args(["--relative", "0.2", "--no-curvature-limit", "--check"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("acceptance: FAIL") && stdout.contains("Hausdorff"),
        "{stdout}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("failed a check"));

    let fails = |args: &[&str], needle: &str| {
        let out = abgs()
            .arg("grid")
            .arg(&input)
            .arg("-o")
            .arg(&out_path)
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    };
    fails(&["--iterations", "0"], "--iterations");
    fails(&["--edge-length=-1"], "edge length");
    fails(&["--relative", "NaN"], "edge length");
    fails(&["--feature-angle", "200"], "feature_angle_deg");
    fails(
        &["--edge-length", "0.1", "--relative", "0.1"],
        "cannot be used with",
    );
    // A sizing grid must carry sizes.
    let plain = input.to_str().unwrap();
    fails(&["--size-from", plain], "has no sizes");
    fails(
        &["--size-from", plain, "--relative", "0.1"],
        "cannot be used with",
    );
}

#[test]
fn eval_reports_json_and_a_table() {
    // A sized bumpy plate (via `abgs size`) against itself and against a 2-face plate.
    let input = bumpy_plate("eval-plate.obj", 20, 6.0);
    let dense = tmp("eval-plate-sized.vtk");
    let st = abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&dense)
        .output()
        .unwrap();
    assert_ok(&st);
    let eval = |candidate: &PathBuf, json: bool| {
        let mut c = abgs();
        c.arg("eval")
            .arg("--reference")
            .arg(&dense)
            .arg("--candidate")
            .arg(candidate)
            .args(["--samples", "5000", "--hausdorff-samples", "5000"]);
        if json {
            c.arg("--json");
        }
        c.output().unwrap()
    };
    let out = eval(&dense, true);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["faces_reference"], 800);
    assert_eq!(v["faces_candidate"], 800);
    assert_eq!(v["reduction"], 0.0);
    assert_eq!(v["size_deviation"]["mean"], 1.0);
    assert_eq!(v["size_deviation"]["max"], 1.0);
    assert_eq!(v["size_deviation"]["samples"], 5000);
    assert!(v["element_count_change"].as_f64().unwrap().abs() < 1e-12);
    assert!(v["hausdorff_relative"].as_f64().unwrap() < 1e-12);
    assert!(v["angles_candidate"]["min_p5"].as_f64().unwrap() > 40.0);
    assert!(v["reference"]
        .as_str()
        .unwrap()
        .ends_with("eval-plate-sized.vtk"));
    // A 2-face flat candidate: reduction, deviation and distance are reported.
    let coarse = sized_grid("eval");
    let out = eval(&coarse, true);
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reduction"], 1.0 - 2.0 / 800.0);
    assert!(v["size_deviation"]["max"].as_f64().unwrap() > 1.0);
    assert!(v["hausdorff"].as_f64().unwrap() > 0.04);
    let text = eval(&coarse, false);
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.status.success() && s.contains("size deviation") && s.contains("element count"),
        "{s}"
    );
    // A candidate without sizes fails with a message.
    let out = eval(&input, false);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no sizes"));
}

/// A plate subdivided n × n with sizes 0.02 + 0.2·x, written as VTK.
fn dense_plate(tag: &str, n: usize) -> PathBuf {
    let path = tmp(&format!("dense-plate-{tag}.vtk"));
    let (v, t) = plate_arrays(n, |_| 0.0);
    let s = v.iter().map(|p| 0.02 + 0.2 * p[0]).collect();
    abgs::Grid::from_arrays(v, t, Some(s), &abgs::BuildOptions::default())
        .unwrap()
        .save(&path)
        .unwrap();
    path
}

#[test]
fn simplify_lbo_and_qem_write_grids_with_sizes_and_a_report() {
    let dense = dense_plate("simp", 30);
    let out = tmp("simp-out.vtk");
    let rep = tmp("simp-report.json");
    let o = abgs()
        .args(["simplify"])
        .arg(&dense)
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(&rep)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let g = abgs::Grid::load(&out).unwrap();
    assert!(g.sizes().is_some());
    assert!(g.triangles().len() < 1800 / 2);
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&rep).unwrap()).unwrap();
    assert_eq!(r["parameters"]["t_size"], 1.2);
    assert_eq!(r["report"]["faces_out"], g.triangles().len());
    let its = r["report"]["iterations"].as_array().unwrap();
    assert!(its.len() >= 2);
    assert_eq!(its.last().unwrap()["faces"], g.triangles().len());
    // The QEM baseline to a face count.
    let q = tmp("simp-qem.vtk");
    let o = abgs()
        .args(["simplify", "--method", "qem", "--target-faces", "100"])
        .arg(&dense)
        .arg("-o")
        .arg(&q)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let g = abgs::Grid::load(&q).unwrap();
    assert!(g.sizes().is_some() && g.triangles().len() <= 100);
    // Errors: qem without a face count, a grid without sizes, bad thresholds.
    for args in [
        vec!["--method", "qem"],
        vec!["--t-size", "1.0"],
        vec!["--fraction", "0"],
    ] {
        let o = abgs()
            .arg("simplify")
            .arg(&dense)
            .arg("-o")
            .arg(&q)
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        assert!(!o.stderr.is_empty());
    }
    let o = abgs()
        .arg("simplify")
        .arg(box_obj("simp"))
        .arg("-o")
        .arg(&q)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no sizes"));
}

#[test]
fn label_writes_one_line_per_edge() {
    let dense = dense_plate("label", 12);
    let out = tmp("labels.csv");
    let o = abgs()
        .arg("label")
        .arg(&dense)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("a,b,ds,dd_rel,de,valid,y"));
    let g = abgs::Grid::load(&dense).unwrap();
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), g.topology().edges.len());
    let mut collapsible = 0;
    for (row, e) in rows.iter().zip(&g.topology().edges) {
        let f: Vec<&str> = row.split(',').collect();
        assert_eq!(f.len(), 7);
        assert_eq!(
            [f[0].parse::<u32>().unwrap(), f[1].parse::<u32>().unwrap()],
            *e
        );
        let y: f64 = f[6].parse().unwrap();
        assert!((0.0..=1.0).contains(&y));
        if f[5] == "0" {
            assert_eq!(y, 1.0);
            assert!(f[2].is_empty());
        } else if y < 0.5 {
            collapsible += 1;
        }
    }
    assert!(collapsible > 0);
}

#[test]
fn run_writes_grids_report_and_pictures() {
    let dir = tmp("run-box");
    let o = abgs()
        .arg("run")
        .arg(box_obj("run"))
        .arg("-o")
        .arg(&dir)
        .args(["--relative", "0.05", "--qem", "--samples", "20000"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "dense.vtk",
        "simplified.vtk",
        "qem.vtk",
        "report.json",
        "preview.png",
        "convergence.png",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let dense = abgs::Grid::load(&dir.join("dense.vtk")).unwrap();
    let simp = abgs::Grid::load(&dir.join("simplified.vtk")).unwrap();
    assert_eq!(r["counts"]["dense_faces"], dense.triangles().len());
    assert_eq!(r["counts"]["simplified_faces"], simp.triangles().len());
    assert!(simp.triangles().len() < dense.triangles().len());
    let m = &r["metrics"];
    assert!(m["reduction"].as_f64().unwrap() > 0.0);
    assert!(m["size_deviation"]["p95"].as_f64().unwrap() <= 1.2);
    assert!(m["hausdorff_relative"].as_f64().unwrap() < 1e-3);
    assert!(r["qem"]["metrics"]["reduction"].is_number());
    for stage in [
        "dense grid",
        "sizes",
        "simplify",
        "evaluate",
        "images",
        "total",
    ] {
        assert!(r["seconds"][stage].is_number(), "{stage}");
    }
    if cfg!(target_os = "linux") {
        let mem = &r["memory"];
        let peak = mem["peak_rss_bytes"].as_u64().unwrap();
        for stage in ["dense grid", "sizes", "simplify", "evaluate"] {
            let s = mem["stage_peak_rss_bytes"][stage].as_u64().unwrap();
            assert!(0 < s && s <= peak, "{stage}: {s} of {peak}");
        }
        let per_face = mem["peak_bytes_per_dense_face"].as_f64().unwrap();
        // serde_json's default float parser may land one ulp off the
        // written value, so compare to a relative 1e-12.
        let want = peak as f64 / dense.triangles().len() as f64;
        assert!(
            (per_face - want).abs() <= 1e-12 * want,
            "{per_face} vs {want}"
        );
    }
    assert!(!r["iterations"].as_array().unwrap().is_empty());
    assert!(r["parameters"]["simplify"]["tau_d"].is_null());
    assert_eq!(r["parameters"]["simplify"]["clearance_fraction"], 0.25);
    let png = std::fs::read(dir.join("preview.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
