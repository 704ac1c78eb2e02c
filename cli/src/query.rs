//! `abgs query`: sizes at points from a text file.

use crate::Mode;
use abgs::{Error, Result};
use std::io::{BufRead, BufWriter, Write};
use std::path::Path;

/// Reads `x y z` lines (blank lines and `#` comments skipped; commas allowed).
pub fn read_points(path: &Path) -> Result<Vec<[f64; 3]>> {
    let reader: Box<dyn BufRead> = if path == Path::new("-") {
        Box::new(std::io::stdin().lock())
    } else {
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        Box::new(std::io::BufReader::new(f))
    };
    let mut pts = Vec::new();
    for (i, line) in reader.lines().enumerate() {
        let line = line.map_err(|e| Error::io(path, e))?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let v: Vec<&str> = t
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        if v.len() != 3 {
            return Err(Error::parse(
                path,
                format!("line {}: expected 3 numbers, found {}", i + 1, v.len()),
            ));
        }
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = v[k].parse().map_err(|_| {
                Error::parse(path, format!("line {}: '{}' is not a number", i + 1, v[k]))
            })?;
        }
        pts.push(p);
    }
    Ok(pts)
}

/// Runs the query command.
pub fn run(grid: &Path, points: &Path, mode: Mode, beta: f64, output: Option<&Path>) -> Result<()> {
    let g = crate::progress::load(grid)?;
    let pts = read_points(points)?;
    let mut out = vec![0.0; pts.len()];
    match mode {
        Mode::Surface => g.query_sizes(&pts, &mut out)?,
        Mode::Volume => g.query_sizes_volume(&pts, beta, &mut out)?,
    }
    let sink: Box<dyn Write> = match output {
        Some(p) => Box::new(std::fs::File::create(p).map_err(|e| Error::io(p, e))?),
        None => Box::new(std::io::stdout().lock()),
    };
    let mut w = BufWriter::new(sink);
    let name = output.unwrap_or(Path::new("<stdout>"));
    for s in out {
        writeln!(w, "{s}").map_err(|e| Error::io(name, e))?;
    }
    w.flush().map_err(|e| Error::io(name, e))
}
