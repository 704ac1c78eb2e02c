//! Compiles every C program in `ffi_tests/` with `-Wall -Wextra -Werror`
//! (through the `cc` crate, which picks the C compiler and flags), links it
//! against the `libabgs` shared library cargo just built, runs it, and fails
//! on a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// How long one C test may run before it counts as hung: compiling and
/// running all ten took 15 s in a debug build on 2 cores, so this is far from
/// any honest run on a slow machine.
const HANG_LIMIT: Duration = Duration::from_secs(900);

/// Directory holding the cdylib built for this test run (`target/<profile>/deps`).
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let deps = exe.parent().expect("deps dir").to_path_buf();
    for dir in [deps.clone(), deps.parent().unwrap().to_path_buf()] {
        if dir.join("libabgs.so").exists() || dir.join("libabgs.dylib").exists() {
            return dir;
        }
    }
    panic!("libabgs shared library not found next to {}", exe.display());
}

fn compile_and_run(source: &Path, out_dir: &Path, lib: &Path) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let compiler = cc::Build::new()
        .target(env!("ABGS_BUILD_TARGET"))
        .host(env!("ABGS_BUILD_HOST"))
        .opt_level(1)
        .cargo_metadata(false)
        .warnings(true)
        .extra_warnings(true)
        .warnings_into_errors(true)
        .flag("-std=c11")
        .flag("-D_POSIX_C_SOURCE=200809L")
        .include(root.join("include"))
        .include(root.join("ffi_tests"))
        .get_compiler();
    let exe = out_dir.join(source.file_stem().unwrap());
    let mut cmd = compiler.to_command();
    cmd.arg(source)
        .arg("-o")
        .arg(&exe)
        .arg(format!("-L{}", lib.display()))
        .arg("-labgs")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-lpthread")
        .arg("-lm");
    let status = cmd.status().expect("run the C compiler");
    assert!(status.success(), "compiling {} failed", source.display());
    // cargo puts target/<profile> on LD_LIBRARY_PATH, which would beat the rpath.
    // Output goes to files, so a child that fills a pipe cannot block.
    let (log_out, log_err) = (exe.with_extension("stdout"), exe.with_extension("stderr"));
    let mut child = Command::new(&exe)
        .arg(out_dir)
        .env("LD_LIBRARY_PATH", lib)
        .stdout(std::fs::File::create(&log_out).unwrap())
        .stderr(std::fs::File::create(&log_err).unwrap())
        .spawn()
        .expect("run the C test");
    // A hang guard, not a timing check: a C test that deadlocks fails with its
    // name instead of stalling the whole run until CI's limit.
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the C test") {
            break Some(status);
        }
        if start.elapsed() > HANG_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stdout = std::fs::read_to_string(&log_out).unwrap_or_default();
    let stderr = std::fs::read_to_string(&log_err).unwrap_or_default();
    println!(
        "{}: {} ({:.1} s)",
        source.display(),
        stdout.trim(),
        start.elapsed().as_secs_f64()
    );
    let Some(status) = status else {
        panic!(
            "{} still ran after {} s (a deadlock?), killed:\n{stdout}\n{stderr}",
            source.display(),
            HANG_LIMIT.as_secs()
        );
    };
    assert!(
        status.success(),
        "{} failed ({status}):\n{stdout}\n{stderr}",
        source.display()
    );
}

#[test]
fn c_programs_pass() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = lib_dir();
    let tmp = tempfile::Builder::new()
        .prefix("abgs-ffi-tests-")
        .tempdir()
        .unwrap();
    let out_dir = tmp.path().to_path_buf();
    let mut sources: Vec<PathBuf> = std::fs::read_dir(root.join("ffi_tests"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "c"))
        .collect();
    sources.sort();
    assert!(sources.len() >= 4, "C tests missing");
    for s in &sources {
        compile_and_run(s, &out_dir, &lib);
    }
}
