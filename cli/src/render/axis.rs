//! Axis ticks (linear and logarithmic) and their number labels.

/// One tick of an axis: its value and label.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Position on the axis, in data units.
    pub value: f64,
    /// Text drawn next to the tick.
    pub label: String,
}

/// Formats `v` with `sig` significant digits (trailing zeros trimmed): decimal for
/// 0.001 <= |v| < 100000 (e.g. `0.0123`, `250`), scientific otherwise (e.g. `1.2e-4`).
pub fn format_number(v: f64, sig: usize) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let sig = sig.clamp(1, 15);
    let sci = format!("{:.*e}", sig - 1, v);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-3..5).contains(&exp) {
        let decimals = (sig as i32 - 1 - exp).max(0) as usize;
        trim_zeros(format!("{v:.decimals$}"))
    } else {
        format!("{}e{exp}", trim_zeros(mantissa.to_string()))
    }
}

/// Formats `v` like [`format_number`], but with a `k`, `M` or `G` suffix from 10 000 up
/// (for counts: `250k`, `1.7M`).
pub fn format_count(v: f64, sig: usize) -> String {
    let a = v.abs();
    for (unit, suffix) in [(1e9, "G"), (1e6, "M"), (1e3, "k")] {
        if a >= 1e4 && a >= unit && a < unit * 1e4 {
            return format!("{}{suffix}", format_number(v / unit, sig));
        }
    }
    format_number(v, sig)
}

fn trim_zeros(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Decimal exponent of `v` (floor of log10 |v|), corrected for rounding.
fn exponent(v: f64) -> i32 {
    let e = v.abs().log10().floor() as i32;
    if 10f64.powi(e + 1) <= v.abs() {
        e + 1
    } else if 10f64.powi(e) > v.abs() {
        e - 1
    } else {
        e
    }
}

/// The nice step (1, 2 or 5 times a power of ten) at most `raw`, and its exponent.
fn nice_step_below(raw: f64) -> (f64, i32) {
    let e = exponent(raw);
    let base = 10f64.powi(e);
    let m = [5.0, 2.0, 1.0]
        .into_iter()
        .find(|&m| m * base <= raw * (1.0 + 1e-9))
        .unwrap_or(1.0);
    (m * base, e)
}

/// Ticks at the multiples of a nice step in [`lo`, `hi`]: the largest step giving at
/// least `min_count` ticks. Labels carry exactly the digits the step needs;
/// `format` is [`format_number`] or [`format_count`].
pub fn linear_ticks(
    lo: f64,
    hi: f64,
    min_count: usize,
    format: fn(f64, usize) -> String,
) -> Vec<Tick> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return if lo.is_finite() {
            vec![Tick {
                value: lo,
                label: format(lo, 3),
            }]
        } else {
            Vec::new()
        };
    }
    let (step, k) = nice_step_below((hi - lo) / min_count.max(1) as f64);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last)
        .map(|i| {
            let v = i as f64 * step;
            let sig = if i == 0 {
                1
            } else {
                (exponent(v) - k + 1).clamp(1, 15) as usize
            };
            Tick {
                value: v,
                label: format(v, sig),
            }
        })
        .collect()
}

/// Ticks for a logarithmic axis over [`lo`, `hi`] (both > 0): powers of ten, or
/// 1-2-5 multiples, or all nine multiples of each decade, whichever first gives
/// at least `min_count`; nice linear ticks for a range too narrow for that.
pub fn log_ticks(
    lo: f64,
    hi: f64,
    min_count: usize,
    format: fn(f64, usize) -> String,
) -> Vec<Tick> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return linear_ticks(lo, hi, min_count, format);
    }
    let (e0, e1) = (exponent(lo), exponent(hi));
    let sets: [&[f64]; 3] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    for set in sets {
        let mut ticks = Vec::new();
        for e in e0..=e1 {
            for &m in set {
                let v = m * 10f64.powi(e);
                if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                    ticks.push(Tick {
                        value: v,
                        label: format(v, 1),
                    });
                }
            }
        }
        if ticks.len() >= min_count {
            return ticks;
        }
    }
    linear_ticks(lo, hi, min_count, format)
}

/// Indices of the ticks to label so that labels of widths `widths` centred at
/// `positions` (increasing) keep at least `gap` pixels apart: every k-th tick for the
/// smallest k that fits.
pub fn thin_labels(positions: &[f64], widths: &[f64], gap: f64) -> Vec<usize> {
    let n = positions.len();
    for stride in 1..=n.max(1) {
        let keep: Vec<usize> = (0..n).step_by(stride).collect();
        let fits = keep.windows(2).all(|w| {
            let (a, b) = (w[0], w[1]);
            (positions[b] - positions[a]).abs() >= 0.5 * (widths[a] + widths[b]) + gap
        });
        if fits {
            return keep;
        }
    }
    (0..n.min(1)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_axis_number_format() {
        assert_eq!(format_number(0.0123, 3), "0.0123");
        assert_eq!(format_number(0.00123, 2), "0.0012");
        assert_eq!(format_number(0.000123, 2), "1.2e-4");
        assert_eq!(format_number(250.0, 3), "250");
        assert_eq!(format_number(1.5, 3), "1.5");
        assert_eq!(format_number(123456.0, 3), "1.23e5");
        assert_eq!(format_number(-0.5, 1), "-0.5");
        assert_eq!(format_count(1_700_000.0, 2), "1.7M");
        assert_eq!(format_count(250_000.0, 2), "250k");
        assert_eq!(format_count(5000.0, 1), "5000");
    }

    #[test]
    fn render_axis_ticks() {
        let t = linear_ticks(0.0, 1.0, 3, format_number);
        let labels: Vec<&str> = t.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ["0", "0.2", "0.4", "0.6", "0.8", "1"]);
        let t = log_ticks(0.003, 2.0, 3, format_number);
        let labels: Vec<&str> = t.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ["0.01", "0.1", "1"]);
        let t = log_ticks(0.0123, 0.0145, 3, format_number);
        assert!(t.len() >= 3, "{t:?}");
        assert!(t.iter().all(|t| t.value >= 0.0123 && t.value <= 0.0145));
        let t = log_ticks(0.05, 0.3, 3, format_number);
        assert!(t.len() >= 3, "{t:?}");
        assert_eq!(
            thin_labels(&[0.0, 10.0, 20.0, 30.0], &[12.0; 4], 2.0),
            [0, 2]
        );
    }
}
