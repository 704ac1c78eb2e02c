//! Compiles every C program in `ffi_tests/` with `-Wall -Wextra -Werror`
//! (through the `cc` crate, which picks the C compiler and flags), links it
//! against the `libabgs` shared library cargo just built, runs it, and fails
//! on a non-zero exit.

use std::path::{Path, PathBuf};
use std::process::Command;

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
    let output = Command::new(&exe)
        .arg(out_dir)
        .env("LD_LIBRARY_PATH", lib)
        .output()
        .expect("run the C test");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    println!("{}: {}", source.display(), stdout.trim());
    assert!(
        output.status.success(),
        "{} failed ({}):\n{stdout}\n{stderr}",
        source.display(),
        output.status
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
