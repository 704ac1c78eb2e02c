//! Headless PNG rendering: side-by-side previews of triangle grids coloured by a
//! per-vertex size, and line charts of convergence histories.
//!
//! Everything is drawn in software (z-buffered rasterizer, embedded bitmap font)
//! and written with the `png` crate; the same input gives the same bytes.

mod axis;
mod chart;
mod colour;
mod font;
mod raster;

use colour::{colour_bar_height, draw_colour_bar, viridis_lut, LogScale};
use font::{draw_text, fitting_scale, text_height, text_width};
use raster::{draw_mesh, Camera, Image, MeshStyle};
use std::path::Path;

/// Azimuth of the preview camera (degrees about +z, from +x).
pub const AZIMUTH_DEG: f64 = 35.0;
/// Elevation of the preview camera (degrees above the xy plane).
pub const ELEVATION_DEG: f64 = 25.0;

const BACKGROUND: raster::Rgb = [255, 255, 255];
const INK: raster::Rgb = [30, 30, 30];

/// One triangle grid of a preview, coloured by a per-vertex value.
pub struct Panel<'a> {
    /// Text drawn above the panel (e.g. `dense: 163,118 faces`).
    pub title: String,
    /// Vertex coordinates.
    pub vertices: &'a [[f64; 3]],
    /// Triangles (indices into `vertices`); degenerate, out-of-range or
    /// non-finite ones are skipped.
    pub triangles: &'a [[u32; 3]],
    /// One value per vertex, > 0 (sizes); non-finite or <= 0 values (and missing
    /// ones) are drawn grey.
    pub values: &'a [f64],
}

/// Renders the panels side by side (same camera: fitted to the union of all panels' bounding boxes,
/// a fixed oblique view, e.g. azimuth 35°, elevation 25°), with a shared log colour bar captioned `legend`.
///
/// The camera is orthographic, looking from azimuth [`AZIMUTH_DEG`] and elevation
/// [`ELEVATION_DEG`] with z up, and scaled so that the projection of every finite
/// vertex of every panel fits one panel. Faces are coloured per pixel by viridis
/// of the interpolated log value, shaded with a two-sided Lambert term, and their
/// edges drawn where they are long enough on screen: edges shorter than 3 pixels,
/// and those of triangles thinner than a pixel, are left out (fading in up to 12
/// and 3 pixels), so that very dense grids still show their colours.
///
/// Errors on a zero size, no panels, or when the file cannot be written.
pub fn preview_png(
    panels: &[Panel],
    legend: &str,
    width: u32,
    height: u32,
    path: &Path,
) -> Result<(), String> {
    let img = preview_image(panels, legend, width, height)?;
    img.write_png(path)
}

/// Renders the preview of [`preview_png`] into an image.
fn preview_image(panels: &[Panel], legend: &str, width: u32, height: u32) -> Result<Image, String> {
    if width == 0 || height == 0 {
        return Err(format!("invalid image size {width}x{height}"));
    }
    if panels.is_empty() {
        return Err("no panels to render".into());
    }
    let mut img = Image::new(width, height, BACKGROUND);
    let n = panels.len() as u32;
    let gap = 10u32;
    let panel_w = width.saturating_sub(gap.saturating_mul(n.saturating_add(1))) / n;
    let s = if width >= 600 && height >= 300 { 2 } else { 1 };
    let top = 10 + text_height(s) + 8;
    let bar_h = 16;
    let bottom = colour_bar_height(bar_h, s) + 24;
    let panel_h = height.saturating_sub(top + bottom);

    let lut = viridis_lut();
    let values: Vec<&[f64]> = panels.iter().map(|p| p.values).collect();
    let scale = LogScale::from_values(&values);
    let meshes: Vec<&[[f64; 3]]> = panels.iter().map(|p| p.vertices).collect();
    let cam = Camera::fit(&meshes, AZIMUTH_DEG, ELEVATION_DEG, panel_w, panel_h, 0.04);
    let style = MeshStyle {
        lut: &lut,
        invalid: [150, 150, 150],
        ambient: 0.35,
        edge: [15, 15, 30],
        edge_alpha: 0.7,
        fade_from: 3.0,
        fade_to: 12.0,
        thin_from: 1.0,
        thin_to: 3.0,
    };
    for (k, panel) in panels.iter().enumerate() {
        let x0 = gap + k as u32 * (panel_w + gap);
        let title_scale = fitting_scale(&panel.title, panel_w, s);
        let tw = text_width(&panel.title, title_scale);
        let tx = i64::from(x0) + (i64::from(panel_w) - i64::from(tw)) / 2;
        draw_text(&mut img, tx.max(0), 10, &panel.title, title_scale, INK);
        if panel_w == 0 || panel_h == 0 {
            continue;
        }
        let scalar: Vec<f64> = (0..panel.vertices.len())
            .map(|i| panel.values.get(i).map_or(f64::NAN, |&v| scale.position(v)))
            .collect();
        draw_mesh(
            &mut img,
            x0,
            top,
            panel_w,
            panel_h,
            &cam,
            panel.vertices,
            panel.triangles,
            &scalar,
            &style,
        );
        img.stroke_rect(
            i64::from(x0) - 1,
            i64::from(top) - 1,
            i64::from(panel_w) + 2,
            i64::from(panel_h) + 2,
            [190, 190, 190],
        );
    }
    let bar_w = (u64::from(width) * 3 / 5).min(640) as u32;
    let bar_x = i64::from((width - bar_w) / 2);
    let bar_y = i64::from(height.saturating_sub(bottom)) + 14;
    draw_colour_bar(
        &mut img, bar_x, bar_y, bar_w, bar_h, &scale, &lut, legend, s,
    );
    Ok(img)
}

/// One line of a chart.
pub struct Series<'a> {
    /// Legend entry.
    pub name: String,
    /// Value at x = 0, 1, ...; non-finite values leave a gap.
    pub values: &'a [f64],
}

/// Line chart of the series over x = 0..n-1 (x label `x_label`), title `title`.
///
/// All series share one y axis, logarithmic when every value is positive and
/// they span more than a factor of 20 (e.g. face counts next to element
/// estimates), linear otherwise; series take the colours of a fixed palette in order.
/// Errors on a zero size or when the file cannot be written.
pub fn line_chart_png(
    title: &str,
    x_label: &str,
    series: &[Series],
    width: u32,
    height: u32,
    path: &Path,
) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("invalid image size {width}x{height}"));
    }
    let data: Vec<(&str, &[f64])> = series.iter().map(|s| (s.name.as_str(), s.values)).collect();
    chart::line_chart(title, x_label, &data, width, height).write_png(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A unique path in the temporary directory.
    fn temp_png(name: &str) -> PathBuf {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        std::env::temp_dir().join(format!(
            "abgs-render-{name}-{}-{nanos}.png",
            std::process::id()
        ))
    }

    /// Decodes an RGB PNG: width, height and pixels.
    fn decode(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let px = buf[..info.buffer_size()]
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        (info.width, info.height, px)
    }

    /// A UV sphere of radius `r` around `c`, sized by its z coordinate.
    fn sphere(c: [f64; 3], r: f64, n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<f64>) {
        let mut v = Vec::new();
        for i in 0..=n {
            let th = std::f64::consts::PI * f64::from(i) / f64::from(n);
            for j in 0..2 * n {
                let ph = std::f64::consts::PI * f64::from(j) / f64::from(n);
                v.push([
                    c[0] + r * th.sin() * ph.cos(),
                    c[1] + r * th.sin() * ph.sin(),
                    c[2] + r * th.cos(),
                ]);
            }
        }
        let mut t = Vec::new();
        let id = |i: u32, j: u32| i * 2 * n + j % (2 * n);
        for i in 0..n {
            for j in 0..2 * n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let s = v.iter().map(|p| 0.01 * (2.0 + p[2] - c[2]).exp()).collect();
        (v, t, s)
    }

    fn is_coloured(p: [u8; 3]) -> bool {
        p != BACKGROUND && !(p[0] == p[1] && p[1] == p[2])
    }

    #[test]
    fn render_preview_two_panels() {
        let (v, t, s) = sphere([0.0; 3], 1.0, 24);
        let (v2, t2, s2) = sphere([0.0; 3], 1.0, 8);
        let panels = [
            Panel {
                title: format!("dense: {} faces", t.len()),
                vertices: &v,
                triangles: &t,
                values: &s,
            },
            Panel {
                title: format!("simplified: {} faces", t2.len()),
                vertices: &v2,
                triangles: &t2,
                values: &s2,
            },
        ];
        let path = temp_png("preview");
        preview_png(&panels, "size h", 800, 450, &path).unwrap();
        let (w, h, px) = decode(&path);
        std::fs::remove_file(&path).ok();
        assert_eq!((w, h), (800, 450));
        let at = |x: u32, y: u32| px[(y * w + x) as usize];
        // Panels: x = 10 + k·395, 385 wide; y = 36..(450 - 90).
        let cy = (36 + (450 - 90)) / 2;
        for cx in [10 + 385 / 2, 10 + 395 + 385 / 2] {
            assert!(
                is_coloured(at(cx, cy)),
                "panel centre {cx} {:?}",
                at(cx, cy)
            );
            let count = (0..385)
                .flat_map(|dx| (40..300).map(move |y| (cx - 192 + dx, y)))
                .filter(|&(x, y)| is_coloured(at(x, y)))
                .count();
            assert!(count > 10_000, "panel at {cx}: {count} coloured pixels");
        }
        // Same input, same bytes.
        let a = temp_png("same-a");
        let b = temp_png("same-b");
        preview_png(&panels, "size h", 640, 360, &a).unwrap();
        preview_png(&panels, "size h", 640, 360, &b).unwrap();
        let (da, db) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        std::fs::remove_file(&a).ok();
        std::fs::remove_file(&b).ok();
        assert_eq!(da, db);
    }

    #[test]
    fn render_preview_degenerate_input() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [f64::NAN, 1.0, 0.0],
            [2.0, 0.0, 0.0],
        ];
        let t = [[0, 1, 2], [0, 1, 3], [0, 0, 0], [0, 1, 7]];
        let panels = [
            Panel {
                title: "broken".into(),
                vertices: &v,
                triangles: &t,
                values: &[0.0, -1.0],
            },
            Panel {
                title: "empty".into(),
                vertices: &[],
                triangles: &[],
                values: &[],
            },
        ];
        let path = temp_png("degenerate");
        preview_png(&panels, "size h", 300, 200, &path).unwrap();
        let (w, h, _) = decode(&path);
        std::fs::remove_file(&path).ok();
        assert_eq!((w, h), (300, 200));
        assert!(preview_png(&panels, "h", 0, 10, &path).is_err());
        assert!(preview_png(&[], "h", 10, 10, &path).is_err());
        // A tiny image must not panic either.
        let img = preview_image(&panels, "size h", 3, 2).unwrap();
        assert_eq!((img.width(), img.height()), (3, 2));
    }

    #[test]
    fn render_chart_has_line_colours() {
        let faces = [1.7e6, 6e5, 3e5, 2e5, 1.7e5, 1.63e5];
        let elements = [5.1e4, 5.3e4, 5.5e4, 5.55e4, 5.6e4, 5.6e4];
        let series = [
            Series {
                name: "faces".into(),
                values: &faces,
            },
            Series {
                name: "estimated elements".into(),
                values: &elements,
            },
        ];
        let path = temp_png("chart");
        line_chart_png("convergence", "iteration", &series, 640, 400, &path).unwrap();
        let (w, h, px) = decode(&path);
        std::fs::remove_file(&path).ok();
        assert_eq!((w, h), (640, 400));
        for c in &chart::PALETTE[..2] {
            let count = px.iter().filter(|p| *p == c).count();
            assert!(count > 100, "colour {c:?}: {count} pixels");
        }
        // Empty and single-point series do not panic.
        let empty = [Series {
            name: "none".into(),
            values: &[],
        }];
        line_chart_png("t", "x", &empty, 200, 100, &path).unwrap();
        line_chart_png("t", "x", &[], 50, 20, &path).unwrap();
        std::fs::remove_file(&path).ok();
    }
}
