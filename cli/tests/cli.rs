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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    for ext in ["msh", "vtu", "ply", "mesh"] {
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    let n = 30;
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            v.push([x, y, 0.05 * (8.0 * x).sin()]);
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
    let input = tmp("bumpy.obj");
    abgs::Grid::from_arrays(v, t, None, &abgs::BuildOptions::default())
        .unwrap()
        .save(&input)
        .unwrap();
    let out = tmp("bumpy-sized.vtk");
    let st = abgs()
        .arg("size")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--beta", "1.3", "--source", "point 0.5 0.5 0 0.003 0.05"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
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
