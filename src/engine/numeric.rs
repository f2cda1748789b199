//! Small numerical helpers shared by the engine: rounding for files,
//! medians and quantiles of samples.

/// `value` rounded to `decimals` decimal places (half away from zero).
#[must_use]
pub fn round_to(value: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (value * scale).round() / scale
}

/// `value` as it reads back after being written with `decimals` decimals
/// (`{:.decimals$}`): a number a report shows, kept as shown so that the
/// text written from it is the text read back.
#[must_use]
pub fn as_written(value: f64, decimals: usize) -> f64 {
    format!("{value:.decimals$}").parse().unwrap_or(value)
}
