//! Plain quadric-error decimation of a (sized) grid to a face count, the
//! baseline of the sizing-aware simplifier: prints the faces reached, the
//! seconds spent and the Hausdorff distance to the input over its diagonal,
//! and saves the result (sizes re-projected from the input when it has them).
//!
//! `cargo run --release --example qem_decimate -- SIZED.vtk FACES OUT.vtk`

use abgs::qem::{decimate, QemParams};
use abgs::remesh::quality::hausdorff;
use abgs::Grid;
use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, faces, output] = &args[..] else {
        eprintln!("usage: qem_decimate SIZED.vtk FACES OUT.vtk");
        return ExitCode::FAILURE;
    };
    let Ok(target_faces) = faces.parse::<usize>() else {
        eprintln!("FACES must be a positive integer, got '{faces}'");
        return ExitCode::FAILURE;
    };
    let run =
        || -> abgs::Result<()> {
            let a = Grid::load(Path::new(input))?;
            let params = QemParams {
                target_faces,
                ..Default::default()
            };
            let d = decimate(&a, &params)?;
            let b = &d.grid;
            let diag = a.bbox().diagonal();
            let h = hausdorff(&a, b, 100_000, 1) / diag;
            println!(
            "{} -> {} faces ({} vertices), {} collapses, {:.3} s, Hausdorff/diag {:.3e}, sizes {}",
            a.triangles().len(),
            b.triangles().len(),
            b.vertices().len(),
            d.collapses,
            d.seconds,
            h,
            if b.sizes().is_some() { "re-projected" } else { "none" }
        );
            b.save(Path::new(output))?;
            println!("wrote {output}");
            Ok(())
        };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
