//! Line charts of series over the iteration index.
//!
//! One y axis shared by all series: logarithmic when every value is positive and
//! they span more than a factor of [`LOG_SPAN`], linear (from zero when the values
//! are non-negative and not crowded near their maximum) otherwise.

use super::axis::{format_count, linear_ticks, log_ticks, thin_labels, Tick};
use super::font::{cap_height, draw_text, fitting_scale, text_height, text_width};
use super::raster::{Image, Rgb};

/// Smallest ratio of the largest to the smallest value for a logarithmic y axis.
pub const LOG_SPAN: f64 = 20.0;

/// Series colours, in order (the matplotlib "tab10" palette); repeated past the end.
pub const PALETTE: [Rgb; 8] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
];

const INK: Rgb = [30, 30, 30];
const GRID: Rgb = [225, 225, 225];

/// The y axis: range, scale kind and ticks.
struct YAxis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Vec<Tick>,
}

impl YAxis {
    fn new(series: &[(&str, &[f64])]) -> YAxis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in series
            .iter()
            .flat_map(|s| s.1.iter())
            .filter(|v| v.is_finite())
        {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        }
        if lo > 0.0 && hi / lo > LOG_SPAN {
            let (a, b) = (lo.ln(), hi.ln());
            let pad = 0.04 * (b - a);
            let (lo, hi) = ((a - pad).exp(), (b + pad).exp());
            let ticks = log_ticks(lo, hi, 3, format_count);
            return YAxis {
                lo,
                hi,
                log: true,
                ticks,
            };
        }
        if lo >= 0.0 && lo <= 0.4 * hi {
            lo = 0.0;
        }
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
            let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo, hi) = (lo - pad, hi + pad);
            if lo < 0.0 && hi > 0.0 && series.iter().flat_map(|s| s.1.iter()).all(|v| *v >= 0.0) {
                lo = 0.0;
            }
        }
        // Extend the range to whole tick steps.
        let first = linear_ticks(lo, hi, 4, format_count);
        if first.len() >= 2 {
            let step = first[1].value - first[0].value;
            lo = (lo / step + 1e-9).floor() * step;
            hi = (hi / step - 1e-9).ceil() * step;
        }
        let ticks = linear_ticks(lo, hi, 4, format_count);
        YAxis {
            lo,
            hi,
            log: false,
            ticks,
        }
    }

    /// Position of `v` in [0, 1] from bottom to top (NaN when not drawable).
    fn position(&self, v: f64) -> f64 {
        if self.log {
            if v > 0.0 {
                (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
            } else {
                f64::NAN
            }
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

/// Integer x ticks for 0..=`max`: a step of 1, 2 or 5 times a power of ten giving at most 10.
fn x_ticks(max: usize) -> Vec<usize> {
    let mut step = 1usize;
    let mut k = 0;
    while max / step > 10 {
        step = [2, 5, 10][k % 3] * 10usize.pow((k / 3) as u32);
        k += 1;
    }
    (0..=max).step_by(step).collect()
}

/// Renders the chart: `title` on top, the series as lines (with point markers when
/// there are few points) over x = 0..n-1, axes with numbered ticks, `x_label`, and a
/// legend in the corner that covers the fewest points. Non-finite values break the line.
pub fn line_chart(
    title: &str,
    x_label: &str,
    series: &[(&str, &[f64])],
    width: u32,
    height: u32,
) -> Image {
    let mut img = Image::new(width, height, [255, 255, 255]);
    let (w, h) = (i64::from(width), i64::from(height));
    let s = if width >= 480 && height >= 320 { 2 } else { 1 };
    let th = i64::from(text_height(s));
    let title_scale = fitting_scale(title, width.saturating_sub(20), s);
    let title_w = i64::from(text_width(title, title_scale));
    draw_text(&mut img, (w - title_w) / 2, 10, title, title_scale, INK);

    let n = series.iter().map(|s| s.1.len()).max().unwrap_or(0);
    let x_max = n.saturating_sub(1).max(1);
    let y = YAxis::new(series);
    let label_w = y
        .ticks
        .iter()
        .map(|t| i64::from(text_width(&t.label, s)))
        .max()
        .unwrap_or(0);
    let left = label_w + 18;
    let right = w - 24;
    let top = 10 + i64::from(text_height(title_scale)) + 16;
    let bottom = h - (8 + th + 12 + th + 10);
    if right - left < 10 || bottom - top < 10 {
        return img;
    }
    // Points stay `inset` pixels off the left and right of the frame.
    let inset = 10.0;
    let (pw, ph) = ((right - left) as f64 - 2.0 * inset, (bottom - top) as f64);
    let px = |x: f64| left as f64 + inset + x / x_max as f64 * pw;
    let py = |v: f64| bottom as f64 - y.position(v) * ph;

    // Grid and y ticks.
    let y_pos: Vec<f64> = y.ticks.iter().map(|t| py(t.value)).collect();
    for &p in &y_pos {
        img.fill_rect(left, p.round() as i64, right - left, 1, GRID);
    }
    let heights = vec![th as f64; y_pos.len()];
    let mut order: Vec<usize> = (0..y_pos.len()).collect();
    order.reverse(); // Increasing screen position.
    let rev: Vec<f64> = order.iter().map(|&i| y_pos[i]).collect();
    for k in thin_labels(&rev, &heights, 4.0) {
        let i = order[k];
        let lw = i64::from(text_width(&y.ticks[i].label, s));
        img.fill_rect(left - 5, y_pos[i].round() as i64, 5, 1, INK);
        draw_text(
            &mut img,
            left - 9 - lw,
            y_pos[i].round() as i64 - i64::from(cap_height(s)) / 2,
            &y.ticks[i].label,
            s,
            INK,
        );
    }
    // X ticks.
    let xt = x_ticks(x_max);
    let x_pos: Vec<f64> = xt.iter().map(|&x| px(x as f64)).collect();
    let labels: Vec<String> = xt.iter().map(|x| x.to_string()).collect();
    let widths: Vec<f64> = labels.iter().map(|l| f64::from(text_width(l, s))).collect();
    for &p in &x_pos {
        img.fill_rect(p.round() as i64, bottom, 1, 5, INK);
    }
    for i in thin_labels(&x_pos, &widths, 10.0) {
        draw_text(
            &mut img,
            (x_pos[i] - 0.5 * widths[i]).round() as i64,
            bottom + 8,
            &labels[i],
            s,
            INK,
        );
    }
    let xl_w = i64::from(text_width(x_label, s));
    draw_text(
        &mut img,
        left + (right - left - xl_w) / 2,
        bottom + 8 + th + 12,
        x_label,
        s,
        INK,
    );
    img.stroke_rect(left, top, right - left + 1, bottom - top + 1, INK);

    // Series.
    let few = n <= 60;
    for (k, (_, values)) in series.iter().enumerate() {
        let c = PALETTE[k % PALETTE.len()];
        let pts: Vec<Option<[f64; 2]>> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let q = [px(i as f64), py(v)];
                (v.is_finite() && q[1].is_finite()).then_some(q)
            })
            .collect();
        for pair in pts.windows(2) {
            if let (Some(a), Some(b)) = (pair[0], pair[1]) {
                img.line(a, b, 2.5, c);
            }
        }
        for q in pts.iter().flatten() {
            if few || pts.len() == 1 {
                img.line(*q, *q, 7.0, c);
            }
        }
    }
    draw_legend(&mut img, series, [left, top, right, bottom], s, &|i, v| {
        [px(i as f64), py(v)]
    });
    img
}

/// Draws the legend box in the plot corner (of `plot` = [left, top, right, bottom])
/// that covers the fewest series points; `at` maps (index, value) to pixels.
fn draw_legend(
    img: &mut Image,
    series: &[(&str, &[f64])],
    plot: [i64; 4],
    s: u32,
    at: &dyn Fn(usize, f64) -> [f64; 2],
) {
    if series.is_empty() {
        return;
    }
    let th = i64::from(text_height(s));
    let cap = i64::from(cap_height(s));
    let line_h = th + 6;
    let name_w = series
        .iter()
        .map(|(n, _)| i64::from(text_width(n, s)))
        .max()
        .unwrap_or(0);
    let bw = 10 + 28 + 8 + name_w + 10;
    let bh = 8 + line_h * series.len() as i64;
    let [left, top, right, bottom] = plot;
    let corners = [
        (right - 8 - bw, top + 8),
        (right - 8 - bw, bottom - 8 - bh),
        (left + 8, top + 8),
        (left + 8, bottom - 8 - bh),
    ];
    // Samples along the lines that fall in the box at (x, y).
    let covered = |(x, y): (i64, i64)| -> usize {
        let inside = |q: [f64; 2]| {
            q[0] >= x as f64 - 4.0
                && q[0] <= (x + bw) as f64 + 4.0
                && q[1] >= y as f64 - 4.0
                && q[1] <= (y + bh) as f64 + 4.0
        };
        let mut count = 0;
        for (_, values) in series {
            for i in 0..values.len() {
                let a = at(i, values[i]);
                let b = if i + 1 < values.len() {
                    at(i + 1, values[i + 1])
                } else {
                    a
                };
                for k in 0..16 {
                    let t = f64::from(k) / 16.0;
                    let q = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                    count += usize::from(inside(q));
                }
            }
        }
        count
    };
    let (x, y) = corners
        .iter()
        .copied()
        .min_by_key(|&c| covered(c))
        .unwrap_or(corners[0]);
    img.fill_rect(x, y, bw, bh, [255, 255, 255]);
    img.stroke_rect(x, y, bw, bh, [160, 160, 160]);
    for (k, (name, _)) in series.iter().enumerate() {
        let c = PALETTE[k % PALETTE.len()];
        let cy = y + 8 + k as i64 * line_h + cap / 2;
        img.line(
            [(x + 10) as f64, cy as f64 + 0.5],
            [(x + 38) as f64, cy as f64 + 0.5],
            2.5,
            c,
        );
        draw_text(img, x + 46, cy - cap / 2, name, s, INK);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_chart_x_ticks() {
        assert_eq!(x_ticks(5), [0, 1, 2, 3, 4, 5]);
        assert_eq!(x_ticks(20), [0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20]);
        assert_eq!(x_ticks(100).len(), 11);
        assert!(x_ticks(1000).len() <= 11);
    }

    #[test]
    fn render_chart_axis_kinds() {
        let a: &[f64] = &[1.7e6, 5e5, 2e5, 1.6e5];
        let b: &[f64] = &[5e4, 5.2e4, 5.5e4, 5.6e4];
        let y = YAxis::new(&[("faces", a), ("elements", b)]);
        assert!(y.log && y.ticks.len() >= 3);
        let y = YAxis::new(&[("faces", a)]);
        assert!(!y.log && y.lo == 0.0 && y.hi >= 1.7e6);
        let y = YAxis::new(&[("flat", &[3.0, 3.0][..])]);
        assert!(y.lo < 3.0 && y.hi > 3.0);
        let y = YAxis::new(&[]);
        assert!(y.lo < y.hi);
    }
}
