//! RGB image buffer, PNG output, anti-aliased 2D lines, and the orthographic
//! camera with the z-buffered triangle rasterizer used for mesh panels.
//!
//! Mesh panels are rasterized in horizontal bands of rows, one rayon task per
//! band; each band visits its triangles in input order, so the output does not
//! depend on the thread count. Edges are drawn by the fragment that wins the
//! depth test (its distance to its own edges), so hidden edges never show.

use rayon::prelude::*;
use std::io::BufWriter;
use std::path::Path;

/// An 8-bit RGB colour.
pub type Rgb = [u8; 3];

/// An RGB image, rows top to bottom.
#[derive(Clone, Debug)]
pub struct Image {
    width: u32,
    height: u32,
    data: Vec<u8>,
}

impl Image {
    /// A `width`×`height` image filled with `background`.
    pub fn new(width: u32, height: u32, background: Rgb) -> Image {
        let n = width as usize * height as usize;
        let mut data = Vec::with_capacity(n * 3);
        for _ in 0..n {
            data.extend_from_slice(&background);
        }
        Image {
            width,
            height,
            data,
        }
    }

    /// Width in pixels.
    #[cfg(test)]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[cfg(test)]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Colour of pixel (`x`, `y`); panics outside the image.
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Sets pixel (`x`, `y`) if it lies in the image.
    pub fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && x < i64::from(self.width) && y < i64::from(self.height) {
            let i = (y as usize * self.width as usize + x as usize) * 3;
            self.data[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Mixes `c` into pixel (`x`, `y`) with opacity `alpha` in [0, 1], if it lies in the image.
    pub fn blend(&mut self, x: i64, y: i64, c: Rgb, alpha: f64) {
        if x >= 0 && y >= 0 && x < i64::from(self.width) && y < i64::from(self.height) {
            let a = alpha.clamp(0.0, 1.0);
            let i = (y as usize * self.width as usize + x as usize) * 3;
            for k in 0..3 {
                let old = f64::from(self.data[i + k]);
                self.data[i + k] = (old + (f64::from(c[k]) - old) * a).round() as u8;
            }
        }
    }

    /// Fills the rectangle of size `w`×`h` at (`x`, `y`), clipped to the image.
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        let x0 = x.max(0);
        let y0 = y.max(0);
        let x1 = (x + w).min(i64::from(self.width));
        let y1 = (y + h).min(i64::from(self.height));
        for py in y0..y1 {
            for px in x0..x1 {
                self.set(px, py, c);
            }
        }
    }

    /// Draws the one-pixel outline of the rectangle of size `w`×`h` at (`x`, `y`).
    pub fn stroke_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        if w <= 0 || h <= 0 {
            return;
        }
        self.fill_rect(x, y, w, 1, c);
        self.fill_rect(x, y + h - 1, w, 1, c);
        self.fill_rect(x, y, 1, h, c);
        self.fill_rect(x + w - 1, y, 1, h, c);
    }

    /// Draws an anti-aliased segment of total width `width` (pixels, round caps)
    /// between two points given in pixel coordinates (pixel centres at +0.5).
    /// Non-finite endpoints draw nothing.
    pub fn line(&mut self, a: [f64; 2], b: [f64; 2], width: f64, c: Rgb) {
        if !(a[0].is_finite() && a[1].is_finite() && b[0].is_finite() && b[1].is_finite()) {
            return;
        }
        let r = 0.5 * width.max(0.0);
        let pad = r + 1.0;
        let x0 = (a[0].min(b[0]) - pad).floor().max(0.0) as i64;
        let y0 = (a[1].min(b[1]) - pad).floor().max(0.0) as i64;
        let x1 = (a[0].max(b[0]) + pad).ceil().min(f64::from(self.width)) as i64;
        let y1 = (a[1].max(b[1]) + pad).ceil().min(f64::from(self.height)) as i64;
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        for py in y0..y1 {
            for px in x0..x1 {
                let p = [px as f64 + 0.5 - a[0], py as f64 + 0.5 - a[1]];
                let t = if len2 > 0.0 {
                    ((p[0] * d[0] + p[1] * d[1]) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let q = [p[0] - t * d[0], p[1] - t * d[1]];
                let dist = (q[0] * q[0] + q[1] * q[1]).sqrt();
                let cover = (r + 0.5 - dist).clamp(0.0, 1.0);
                if cover > 0.0 {
                    self.blend(px, py, c, cover);
                }
            }
        }
    }

    /// Writes the image as an 8-bit RGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err("cannot write an empty image".into());
        }
        let file = std::fs::File::create(path)
            .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut enc = png::Encoder::new(BufWriter::new(file), self.width, self.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let err = |e: png::EncodingError| format!("cannot write {}: {e}", path.display());
        let mut writer = enc.write_header().map_err(err)?;
        writer.write_image_data(&self.data).map_err(err)?;
        writer.finish().map_err(err)
    }
}

/// Orthographic camera: a rotation to view axes, then a scale and shift to pixels.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    right: [f64; 3],
    up: [f64; 3],
    /// Unit vector from the scene towards the viewer.
    toward: [f64; 3],
    /// Light direction (unit, from the surface towards the light).
    light: [f64; 3],
    centre: [f64; 2],
    scale: f64,
    /// Pixel position of `centre` inside a panel (relative to its top-left corner).
    origin: [f64; 2],
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

impl Camera {
    /// A camera looking from azimuth `azimuth_deg` (about +z, from +x) and elevation
    /// `elevation_deg` (z up), scaled so that every finite vertex of `meshes` fits a
    /// `width`×`height` panel with a `margin` fraction left free on each side.
    /// The same camera serves every mesh.
    pub fn fit(
        meshes: &[&[[f64; 3]]],
        azimuth_deg: f64,
        elevation_deg: f64,
        width: u32,
        height: u32,
        margin: f64,
    ) -> Camera {
        let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let toward = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        let right = [-a.sin(), a.cos(), 0.0];
        let up = cross(toward, right);
        let light = normalize([
            toward[0] + 0.5 * up[0] - 0.35 * right[0],
            toward[1] + 0.5 * up[1] - 0.35 * right[1],
            toward[2] + 0.5 * up[2] - 0.35 * right[2],
        ]);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for mesh in meshes {
            for p in mesh.iter() {
                if p.iter().all(|c| c.is_finite()) {
                    let q = [dot(*p, right), dot(*p, up)];
                    for k in 0..2 {
                        lo[k] = lo[k].min(q[k]);
                        hi[k] = hi[k].max(q[k]);
                    }
                }
            }
        }
        let (centre, extent) = if lo[0] <= hi[0] {
            (
                [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
                [hi[0] - lo[0], hi[1] - lo[1]],
            )
        } else {
            ([0.0, 0.0], [1.0, 1.0])
        };
        // A flat or point-like scene is framed as if it had a small extent.
        let e = extent[0].max(extent[1]);
        let extent = if e.is_finite() && e > 0.0 {
            [extent[0].max(1e-3 * e), extent[1].max(1e-3 * e)]
        } else {
            [1.0, 1.0]
        };
        let free = (1.0 - 2.0 * margin).max(0.1);
        let sx = f64::from(width.max(1)) * free / extent[0];
        let sy = f64::from(height.max(1)) * free / extent[1];
        let scale = sx.min(sy);
        Camera {
            right,
            up,
            toward,
            light,
            centre,
            scale,
            origin: [0.5 * f64::from(width), 0.5 * f64::from(height)],
        }
    }

    /// Panel pixel coordinates (x right, y down) and depth (smaller is nearer) of `p`.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        [
            self.origin[0] + (dot(p, self.right) - self.centre[0]) * self.scale,
            self.origin[1] - (dot(p, self.up) - self.centre[1]) * self.scale,
            -dot(p, self.toward),
        ]
    }

    /// Shading factor in [`ambient`, 1] of a face with (not necessarily unit) normal `n`;
    /// both sides are lit alike. `None` for a zero or non-finite normal.
    pub fn shade(&self, n: [f64; 3], ambient: f64) -> Option<f64> {
        let len = dot(n, n).sqrt();
        if !(len.is_finite() && len > 0.0) {
            return None;
        }
        let lambert = (dot(n, self.light) / len).abs();
        Some(ambient + (1.0 - ambient) * lambert)
    }
}

/// How a mesh panel is drawn: colour lookup, edges and their fading.
pub struct MeshStyle<'a> {
    /// Colour of scalar position 0..=255 (index `t·255`).
    pub lut: &'a [Rgb; 256],
    /// Colour of faces with an invalid value.
    pub invalid: Rgb,
    /// Ambient share of the shading.
    pub ambient: f64,
    /// Edge colour.
    pub edge: Rgb,
    /// Largest edge opacity.
    pub edge_alpha: f64,
    /// Projected edge length (pixels) below which edges are not drawn.
    pub fade_from: f64,
    /// Projected edge length (pixels) from which edges are drawn at full opacity.
    pub fade_to: f64,
    /// Smallest projected altitude (pixels) of a triangle below which its edges are
    /// not drawn (a sliver would be all edge).
    pub thin_from: f64,
    /// Smallest projected altitude (pixels) from which a triangle's edges are not faded.
    pub thin_to: f64,
}

/// Rows per rasterization band.
const BAND: usize = 32;

/// One projected triangle ready for rasterization.
struct Tri {
    p: [[f64; 3]; 3],
    t: [f64; 3],
    shade: f64,
    /// Edge opacity by opposite vertex.
    edge_alpha: [f64; 3],
    /// Twice the signed screen area (positive).
    area2: f64,
    /// Length of the edge opposite each vertex (pixels).
    len: [f64; 3],
}

/// Ramp from 0 at `from` to 1 at `to`.
fn ramp(x: f64, from: f64, to: f64) -> f64 {
    ((x - from) / (to - from).max(1e-9)).clamp(0.0, 1.0)
}

/// Projects triangle `f`; `None` when it is degenerate, off-screen in depth, or has
/// out-of-range indices or non-finite coordinates.
fn setup(
    f: [u32; 3],
    vertices: &[[f64; 3]],
    screen: &[[f64; 3]],
    scalar: &[f64],
    cam: &Camera,
    style: &MeshStyle,
) -> Option<Tri> {
    let idx = [f[0] as usize, f[1] as usize, f[2] as usize];
    if idx.iter().any(|&i| i >= vertices.len()) {
        return None;
    }
    let mut p = [screen[idx[0]], screen[idx[1]], screen[idx[2]]];
    if p.iter().flatten().any(|c| !c.is_finite()) {
        return None;
    }
    let mut t = [scalar[idx[0]], scalar[idx[1]], scalar[idx[2]]];
    let w = [vertices[idx[0]], vertices[idx[1]], vertices[idx[2]]];
    let e1 = [w[1][0] - w[0][0], w[1][1] - w[0][1], w[1][2] - w[0][2]];
    let e2 = [w[2][0] - w[0][0], w[2][1] - w[0][1], w[2][2] - w[0][2]];
    let shade = cam.shade(cross(e1, e2), style.ambient)?;
    let mut area2 =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    if !area2.is_finite() || area2 == 0.0 {
        return None;
    }
    if area2 < 0.0 {
        p.swap(1, 2);
        t.swap(1, 2);
        area2 = -area2;
    }
    let d = |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    let len = [d(p[1], p[2]), d(p[2], p[0]), d(p[0], p[1])];
    // Smallest altitude: twice the area over the longest edge.
    let altitude = area2 / len[0].max(len[1]).max(len[2]);
    let thin = style.edge_alpha * ramp(altitude, style.thin_from, style.thin_to);
    let edge_alpha = [
        thin * ramp(len[0], style.fade_from, style.fade_to),
        thin * ramp(len[1], style.fade_from, style.fade_to),
        thin * ramp(len[2], style.fade_from, style.fade_to),
    ];
    Some(Tri {
        p,
        t,
        shade,
        edge_alpha,
        area2,
        len,
    })
}

/// Rasterizes one band (rows `y0..y0 + rows` of a panel `width` wide) of the triangles `faces`.
#[allow(clippy::too_many_arguments)]
fn raster_band(
    y0: usize,
    colour: &mut [Rgb],
    depth: &mut [f64],
    width: usize,
    faces: &[u32],
    triangles: &[[u32; 3]],
    vertices: &[[f64; 3]],
    screen: &[[f64; 3]],
    scalar: &[f64],
    cam: &Camera,
    style: &MeshStyle,
) {
    let rows = depth.len() / width.max(1);
    let y_end = y0 + rows;
    for &fi in faces {
        let Some(tri) = setup(triangles[fi as usize], vertices, screen, scalar, cam, style) else {
            continue;
        };
        let p = tri.p;
        let min_x = p[0][0].min(p[1][0]).min(p[2][0]);
        let max_x = p[0][0].max(p[1][0]).max(p[2][0]);
        let min_y = p[0][1].min(p[1][1]).min(p[2][1]);
        let max_y = p[0][1].max(p[1][1]).max(p[2][1]);
        // Pixel centres x + 0.5 inside [min, max].
        let xa = (min_x - 0.5).ceil().max(0.0) as usize;
        let xb = ((max_x - 0.5).floor() + 1.0).clamp(0.0, width as f64) as usize;
        let ya = ((min_y - 0.5).ceil().max(y0 as f64)) as usize;
        let yb = ((max_y - 0.5).floor() + 1.0).clamp(0.0, y_end as f64) as usize;
        if xa >= xb || ya >= yb {
            continue;
        }
        let inv = 1.0 / tri.area2;
        // Edge function of the edge opposite vertex i: w_i(x, y) = a_i x + b_i y + c_i.
        let coef = |i: usize| {
            let (u, v) = (p[(i + 1) % 3], p[(i + 2) % 3]);
            let a = u[1] - v[1];
            let b = v[0] - u[0];
            let c = u[0] * v[1] - u[1] * v[0];
            [a, b, c]
        };
        let k = [coef(0), coef(1), coef(2)];
        let has_edges = tri.edge_alpha.iter().any(|&a| a > 0.0);
        for y in ya..yb {
            let py = y as f64 + 0.5;
            let row = (y - y0) * width;
            for x in xa..xb {
                let px = x as f64 + 0.5;
                let w = [
                    k[0][0] * px + k[0][1] * py + k[0][2],
                    k[1][0] * px + k[1][1] * py + k[1][2],
                    k[2][0] * px + k[2][1] * py + k[2][2],
                ];
                if w[0] < 0.0 || w[1] < 0.0 || w[2] < 0.0 {
                    continue;
                }
                let b = [w[0] * inv, w[1] * inv, w[2] * inv];
                let z = b[0] * p[0][2] + b[1] * p[1][2] + b[2] * p[2][2];
                let slot = row + x;
                if z >= depth[slot] {
                    continue;
                }
                depth[slot] = z;
                let s = b[0] * tri.t[0] + b[1] * tri.t[1] + b[2] * tri.t[2];
                let base = if s.is_finite() {
                    style.lut[(s.clamp(0.0, 1.0) * 255.0).round() as usize]
                } else {
                    style.invalid
                };
                let mut c = [0.0; 3];
                for j in 0..3 {
                    c[j] = f64::from(base[j]) * tri.shade;
                }
                if has_edges {
                    let mut a: f64 = 0.0;
                    for i in 0..3 {
                        // Distance (pixels) from the pixel centre to the edge opposite i.
                        let dist = w[i] / tri.len[i];
                        a = a.max(tri.edge_alpha[i] * (1.0 - dist).clamp(0.0, 1.0));
                    }
                    for j in 0..3 {
                        c[j] += (f64::from(style.edge[j]) - c[j]) * a;
                    }
                }
                colour[slot] = [c[0].round() as u8, c[1].round() as u8, c[2].round() as u8];
            }
        }
    }
}

/// Rasterizes a triangle mesh into the `width`×`height` panel whose top-left
/// corner is at (`x0`, `y0`) of `img`, coloured by `scalar` (per vertex, in [0, 1]
/// or NaN for invalid) through `style.lut`, shaded and with depth-tested edges.
/// Pixels no triangle covers keep their colour. Returns the number of triangles
/// that were drawn (non-degenerate).
#[allow(clippy::too_many_arguments)]
pub fn draw_mesh(
    img: &mut Image,
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    cam: &Camera,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    scalar: &[f64],
    style: &MeshStyle,
) -> usize {
    let w = width.min(img.width.saturating_sub(x0)) as usize;
    let h = height.min(img.height.saturating_sub(y0)) as usize;
    if w == 0 || h == 0 {
        return 0;
    }
    let screen: Vec<[f64; 3]> = vertices.par_iter().map(|&v| cam.project(v)).collect();
    let scalar: Vec<f64> = (0..vertices.len())
        .map(|i| scalar.get(i).copied().unwrap_or(f64::NAN))
        .collect();
    // Bin the triangles by the bands their rows touch, in input order.
    let n_bands = h.div_ceil(BAND);
    // Band range of each triangle; u32::MAX marks a skipped one, u32::MAX - 1 an off-panel one.
    let ranges: Vec<(u32, u32)> = triangles
        .par_iter()
        .map(|f| {
            let Some(tri) = setup(*f, vertices, &screen, &scalar, cam, style) else {
                return (u32::MAX, 0);
            };
            let min_y = tri.p[0][1].min(tri.p[1][1]).min(tri.p[2][1]);
            let max_y = tri.p[0][1].max(tri.p[1][1]).max(tri.p[2][1]);
            if max_y < 0.0 || min_y > h as f64 {
                return (u32::MAX - 1, 0);
            }
            let ba = ((min_y - 0.5).max(0.0) as usize / BAND).min(n_bands - 1);
            let bb = ((max_y + 0.5).max(0.0) as usize / BAND).min(n_bands - 1);
            (ba as u32, bb as u32)
        })
        .collect();
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    let mut drawn = 0;
    for (fi, &(ba, bb)) in ranges.iter().enumerate() {
        if ba == u32::MAX {
            continue;
        }
        drawn += 1;
        if ba == u32::MAX - 1 {
            continue;
        }
        for bin in &mut bins[ba as usize..=bb as usize] {
            bin.push(fi as u32);
        }
    }
    // Copy the panel region out, rasterize the bands in parallel, copy back.
    let mut colour: Vec<Rgb> = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            colour.push(img.get(x0 + x as u32, y0 + y as u32));
        }
    }
    let mut depth = vec![f64::INFINITY; w * h];
    colour
        .par_chunks_mut(BAND * w)
        .zip(depth.par_chunks_mut(BAND * w))
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(band, ((c, d), faces))| {
            raster_band(
                band * BAND,
                c,
                d,
                w,
                faces,
                triangles,
                vertices,
                &screen,
                &scalar,
                cam,
                style,
            );
        });
    for y in 0..h {
        for x in 0..w {
            img.set(
                i64::from(x0) + x as i64,
                i64::from(y0) + y as i64,
                colour[y * w + x],
            );
        }
    }
    drawn
}

#[cfg(test)]
mod tests {
    use super::*;

    fn style(lut: &[Rgb; 256]) -> MeshStyle<'_> {
        MeshStyle {
            lut,
            invalid: [128, 128, 128],
            ambient: 0.3,
            edge: [0, 0, 0],
            edge_alpha: 0.8,
            fade_from: 3.0,
            fade_to: 8.0,
            thin_from: 1.0,
            thin_to: 3.0,
        }
    }

    #[test]
    fn render_raster_front_triangle_wins_depth_test() {
        let mut img = Image::new(50, 50, [255, 255, 255]);
        // Two overlapping squares seen from +x; the one at larger x is nearer.
        let v = [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.2, 0.2],
            [1.0, 0.8, 0.2],
            [1.0, 0.8, 0.8],
        ];
        let t = [[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        let cam = Camera::fit(&[&v], 0.0, 0.0, 50, 50, 0.05);
        let near = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let lut: [Rgb; 256] =
            std::array::from_fn(|i| if i < 128 { [255, 0, 0] } else { [0, 0, 255] });
        let n = draw_mesh(&mut img, 0, 0, 50, 50, &cam, &v, &t, &near, &style(&lut));
        assert_eq!(n, 3);
        // Inside the front triangle (near its centroid): blue.
        let c = cam.project([1.0, 0.6, 0.4]);
        let px = img.get(c[0] as u32, c[1] as u32);
        assert!(px[2] > px[0], "{px:?}");
    }

    #[test]
    fn render_raster_skips_degenerate_and_nan() {
        let lut = [[255, 0, 0]; 256];
        let mut img = Image::new(20, 20, [255, 255, 255]);
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [f64::NAN, 0.0, 1.0],
        ];
        let t = [[0, 1, 2], [0, 1, 3], [0, 0, 1], [0, 1, 99]];
        let cam = Camera::fit(&[&v], 35.0, 25.0, 20, 20, 0.05);
        let n = draw_mesh(
            &mut img,
            0,
            0,
            20,
            20,
            &cam,
            &v,
            &t,
            &[1.0; 4],
            &style(&lut),
        );
        assert_eq!(n, 0);
    }

    #[test]
    fn render_raster_line_covers_its_pixels() {
        let mut img = Image::new(20, 20, [255, 255, 255]);
        img.line([2.0, 10.0], [18.0, 10.0], 2.0, [0, 0, 0]);
        assert_eq!(img.get(10, 9), [0, 0, 0]);
        assert_eq!(img.get(10, 2), [255, 255, 255]);
        img.line([f64::NAN, 0.0], [1.0, 1.0], 2.0, [0, 0, 0]);
    }
}
