//! The one style every chart shares: a colour-blind-safe palette, the ticks of linear and
//! logarithmic axes, and how their numbers are written. Log axes are ticked at decades (with
//! the 2–9 multiples as light lines) and labelled 0.001 … 1000 or 10⁻⁵; linear axes at
//! 1, 2 or 5 × 10ᵏ steps, written with no more decimals than the step needs.

use plotters::style::RGBColor;

/// Okabe & Ito's colour-blind-safe palette (black first, yellow left out: too pale on white).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
];

/// An outcome that went well, went wrong, or lies between (the stability map's markers).
pub const GOOD: RGBColor = RGBColor(0, 158, 115);
pub const BAD: RGBColor = RGBColor(213, 94, 0);
pub const BETWEEN: RGBColor = RGBColor(230, 159, 0);

/// The ticks of one axis, in the axis's own coordinate (log10 of the value on a log axis).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ticks {
    /// Labelled ticks.
    pub major: Vec<f64>,
    /// Light grid lines between them.
    pub minor: Vec<f64>,
    /// The step between major ticks on a linear axis (0 on a log axis), for their decimals.
    pub step: f64,
}

/// Ticks of a log axis spanning log10 values [lo, hi]: the decades inside it, and where fewer
/// than two fit, the 2 and 5 multiples as well.
pub fn log_ticks(lo: f64, hi: f64) -> Ticks {
    let inside = |v: &f64| *v >= lo - 1e-9 && *v <= hi + 1e-9;
    let decades: Vec<i32> = ((lo.floor() as i32)..=(hi.ceil() as i32)).collect();
    let at = |d: i32, k: f64| d as f64 + k.log10();
    let mut major: Vec<f64> = decades.iter().map(|&d| d as f64).filter(inside).collect();
    if major.len() < 2 {
        major = decades
            .iter()
            .flat_map(|&d| [at(d, 1.0), at(d, 2.0), at(d, 5.0)])
            .filter(inside)
            .collect();
    }
    let minor = decades
        .iter()
        .flat_map(|&d| (2..10).map(move |k| at(d, k as f64)))
        .filter(inside)
        .collect();
    Ticks {
        major,
        minor,
        step: 0.0,
    }
}

/// Ticks of a linear axis over [lo, hi]: three to eight at a 1, 2 or 5 × 10ᵏ step, and five
/// light lines to each step.
pub fn linear_ticks(lo: f64, hi: f64) -> Ticks {
    let span = (hi - lo).abs().max(1e-300);
    let rough = span / 6.0;
    let unit = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * unit)
        .find(|s| span / s <= 8.0)
        .unwrap_or(10.0 * unit);
    let at = |k: f64, s: f64| (k * s * 1e12).round() / 1e12;
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    let major = (first..=last).map(|k| at(k as f64, step)).collect();
    let fine = step / 5.0;
    let minor = ((lo / fine).ceil() as i64..=(hi / fine).floor() as i64)
        .map(|k| at(k as f64, fine))
        .collect();
    Ticks { major, minor, step }
}

/// A tick's label: on a log axis (`log10_value`) the value 10^v as a plain number from 0.001
/// to 10 000, else as 10ⁿ or m×10ⁿ; on a linear axis the value with the step's decimals.
pub fn label(v: f64, log: bool, step: f64) -> String {
    if !log {
        let decimals = if step > 0.0 {
            (-step.log10().floor()).max(0.0) as usize
        } else {
            3
        };
        let text = format!("{v:.decimals$}");
        return if text
            .trim_start_matches('-')
            .chars()
            .all(|c| c == '0' || c == '.')
        {
            "0".into()
        } else {
            text
        };
    }
    let exponent = v.floor();
    let mantissa = 10f64.powf(v - exponent).round();
    let (mantissa, exponent) = if mantissa >= 10.0 {
        (1.0, exponent + 1.0)
    } else {
        (mantissa, exponent)
    };
    let e = exponent as i32;
    if (-3..=4).contains(&e) {
        let value = mantissa * 10f64.powi(e);
        let decimals = (-e).max(0) as usize;
        return format!("{value:.decimals$}");
    }
    let power = format!("10{}", superscript(e));
    if mantissa == 1.0 {
        power
    } else {
        format!("{mantissa}×{power}")
    }
}

/// An integer in Unicode superscript digits.
fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let digits = n.unsigned_abs().to_string();
    let sign = if n < 0 { "⁻" } else { "" };
    sign.chars()
        .chain(digits.bytes().map(|b| DIGITS[(b - b'0') as usize]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_are_ticked_at_decades_and_written_plainly() {
        let t = log_ticks(-3.2, 0.4);
        assert_eq!(t.major, vec![-3.0, -2.0, -1.0, 0.0]);
        assert_eq!(t.minor.len(), 3 + 8 * 3 + 1);
        let labels: Vec<String> = t.major.iter().map(|&v| label(v, true, 0.0)).collect();
        assert_eq!(labels, ["0.001", "0.01", "0.1", "1"]);
        assert_eq!(label(-6.0, true, 0.0), "10⁻⁶");
        assert_eq!(label(5.0_f64.log10() - 7.0, true, 0.0), "5×10⁻⁷");
        // Less than a decade: the 2 and 5 multiples are labelled too.
        let t = log_ticks(0.1, 0.9);
        let labels: Vec<String> = t.major.iter().map(|&v| label(v, true, 0.0)).collect();
        assert_eq!(labels, ["2", "5"]);
    }

    #[test]
    fn linear_axes_take_round_steps_and_no_spare_decimals() {
        let t = linear_ticks(0.0, 3.0);
        assert_eq!(t.step, 0.5);
        let labels: Vec<String> = t.major.iter().map(|&v| label(v, false, t.step)).collect();
        assert_eq!(labels, ["0", "0.5", "1.0", "1.5", "2.0", "2.5", "3.0"]);
        let t = linear_ticks(-12.0, 130.0);
        assert_eq!(t.step, 20.0);
        assert_eq!(label(t.major[0], false, t.step), "0");
        assert_eq!(label(40.0, false, t.step), "40");
    }
}
