//! Small numerical helpers shared by the engine: rounding for files,
//! medians and quantiles of samples.

/// `value` rounded to `decimals` decimal places (half away from zero).
#[must_use]
pub fn round_to(value: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (value * scale).round() / scale
}
