//! Build script: records the target triple so the C tests (tests/ffi_c.rs) can drive
//! the `cc` crate with the same target as the library they link against.
fn main() {
    println!(
        "cargo:rustc-env=ABGS_BUILD_TARGET={}",
        std::env::var("TARGET").unwrap_or_default()
    );
    println!(
        "cargo:rustc-env=ABGS_BUILD_HOST={}",
        std::env::var("HOST").unwrap_or_default()
    );
    println!("cargo:rerun-if-changed=build.rs");
}
