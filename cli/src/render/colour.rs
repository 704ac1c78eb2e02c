//! The viridis colour map, the logarithmic value scale and the colour bar legend.

use super::axis::{format_number, log_ticks, thin_labels};
use super::font::{draw_text, text_height, text_width};
use super::raster::{Image, Rgb};

/// Viridis at `t` in [0, 1] (clamped), from the polynomial fit of the matplotlib
/// table (within about 1% of it).
pub fn viridis(t: f64) -> Rgb {
    const C: [[f64; 3]; 7] = [
        [
            0.277_727_327_223_417_7,
            0.005_407_344_544_966_578,
            0.334_099_805_335_306_1,
        ],
        [
            0.105_093_043_108_577_4,
            1.404_613_529_898_575,
            1.384_590_162_594_685,
        ],
        [
            -0.330_861_828_725_556_3,
            0.214_847_559_468_213,
            0.095_095_163_028_236_59,
        ],
        [
            -4.634_230_498_983_486,
            -5.799_100_973_351_585,
            -19.332_440_956_279_87,
        ],
        [
            6.228_269_936_347_081,
            14.179_933_366_805_09,
            56.690_552_600_681_05,
        ],
        [
            4.776_384_997_670_288,
            -13.745_145_377_746_01,
            -65.353_032_633_372_34,
        ],
        [
            -5.435_455_855_934_631,
            4.645_852_612_178_535,
            26.312_435_249_583_2,
        ],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut rgb = [0u8; 3];
    for (k, out) in rgb.iter_mut().enumerate() {
        let v = C.iter().rev().fold(0.0, |acc, c| acc * t + c[k]);
        *out = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    }
    rgb
}

/// Viridis sampled at 256 evenly spaced positions.
pub fn viridis_lut() -> [Rgb; 256] {
    std::array::from_fn(|i| viridis(i as f64 / 255.0))
}

/// A logarithmic map of positive values onto [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogScale {
    /// Value at position 0.
    pub lo: f64,
    /// Value at position 1 (> `lo`).
    pub hi: f64,
}

impl LogScale {
    /// The range of the finite, positive values of all `sets`; widened to a factor
    /// of 1.5 either side when they are all equal, and [1, 10] when there are none.
    pub fn from_values(sets: &[&[f64]]) -> LogScale {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in sets.iter().flat_map(|s| s.iter()) {
            if v.is_finite() && *v > 0.0 {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            LogScale { lo: 1.0, hi: 10.0 }
        } else if hi <= lo * (1.0 + 1e-12) {
            LogScale {
                lo: lo / 1.5,
                hi: hi * 1.5,
            }
        } else {
            LogScale { lo, hi }
        }
    }

    /// Position of `v` in [0, 1] (clamped); NaN when `v` is not finite or not positive.
    pub fn position(&self, v: f64) -> f64 {
        if !(v.is_finite() && v > 0.0) {
            return f64::NAN;
        }
        ((v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())).clamp(0.0, 1.0)
    }
}

/// Height in pixels that [`draw_colour_bar`] uses at text scale `text_scale`.
pub fn colour_bar_height(bar: u32, text_scale: u32) -> u32 {
    bar + 6 + text_height(text_scale) + 8 + text_height(text_scale)
}

/// Draws a horizontal colour bar `w` pixels wide and `bar` pixels tall at (`x`, `y`):
/// the colours of `lut` from `scale.lo` (left) to `scale.hi` (right), a frame, tick
/// marks with labels below it (at least three where the range allows), and
/// `caption` centred below the labels.
#[allow(clippy::too_many_arguments)]
pub fn draw_colour_bar(
    img: &mut Image,
    x: i64,
    y: i64,
    w: u32,
    bar: u32,
    scale: &LogScale,
    lut: &[Rgb; 256],
    caption: &str,
    text_scale: u32,
) {
    let ink = [30, 30, 30];
    let w = i64::from(w.max(2));
    let bar = i64::from(bar.max(2));
    for i in 0..w {
        let t = i as f64 / (w - 1) as f64;
        let c = lut[(t * 255.0).round() as usize];
        img.fill_rect(x + i, y, 1, bar, c);
    }
    img.stroke_rect(x - 1, y - 1, w + 2, bar + 2, ink);
    let ticks = log_ticks(scale.lo, scale.hi, 3, format_number);
    let span = scale.hi.ln() - scale.lo.ln();
    let positions: Vec<f64> = ticks
        .iter()
        .map(|t| x as f64 + (t.value.ln() - scale.lo.ln()) / span * (w - 1) as f64)
        .collect();
    let widths: Vec<f64> = ticks
        .iter()
        .map(|t| f64::from(text_width(&t.label, text_scale)))
        .collect();
    for &p in &positions {
        img.fill_rect(p.round() as i64, y + bar, 1, 5, ink);
    }
    let label_y = y + bar + 6;
    for i in thin_labels(&positions, &widths, 8.0) {
        let lx = (positions[i] - 0.5 * widths[i]).round() as i64;
        draw_text(img, lx, label_y, &ticks[i].label, text_scale, ink);
    }
    let cap_w = i64::from(text_width(caption, text_scale));
    let cap_y = label_y + i64::from(text_height(text_scale)) + 8;
    draw_text(img, x + (w - cap_w) / 2, cap_y, caption, text_scale, ink);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_colour_viridis_matches_reference() {
        // matplotlib viridis at 0, 0.25, 0.5, 0.75, 1.
        let reference = [
            (0.0, [68, 1, 84]),
            (0.25, [59, 82, 139]),
            (0.5, [33, 145, 140]),
            (0.75, [94, 201, 98]),
            (1.0, [253, 231, 37]),
        ];
        for (t, want) in reference {
            let got = viridis(t);
            for k in 0..3 {
                assert!(
                    (i32::from(got[k]) - want[k]).abs() <= 8,
                    "viridis({t}) = {got:?}, want {want:?}"
                );
            }
        }
    }

    #[test]
    fn render_colour_log_scale() {
        let s = LogScale::from_values(&[&[0.01, 1.0, f64::NAN, -1.0], &[0.1]]);
        assert_eq!(s, LogScale { lo: 0.01, hi: 1.0 });
        assert!((s.position(0.1) - 0.5).abs() < 1e-12);
        assert!(s.position(0.0).is_nan());
        assert_eq!(s.position(5.0), 1.0);
        let flat = LogScale::from_values(&[&[2.0, 2.0]]);
        assert!(flat.lo < 2.0 && flat.hi > 2.0);
        assert_eq!(LogScale::from_values(&[]), LogScale { lo: 1.0, hi: 10.0 });
    }
}
