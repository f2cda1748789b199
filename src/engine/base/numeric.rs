//! Small numerical helpers shared by the engine: rounding for files,
//! medians and quantiles of samples, 1-2-5 steps for axes and scale bars.

/// Sweeps a singular value or symmetric eigen decomposition may take
/// before it is abandoned: converging ones take a few per dimension; the
/// bound keeps a matrix with a NaN from spinning forever.
pub const MAX_DECOMPOSITION_SWEEPS: usize = 10_000;

/// A number for a message: as written for everyday sizes, in scientific
/// notation beyond them (`1e160`, not 161 digits).
#[must_use]
pub fn show(value: f64) -> String {
    let a = value.abs();
    if a != 0.0 && !(1e-4..1e7).contains(&a) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// A computed number for a message, to 4 significant digits: `2578`,
/// `0.01524`, `1.5e160` (a reading the user typed is shown whole by
/// [`show`]).
#[must_use]
pub fn approx(value: f64) -> String {
    let a = value.abs();
    if !value.is_finite() || a == 0.0 {
        return format!("{value}");
    }
    if !(1e-4..1e7).contains(&a) {
        return format!("{value:.3e}");
    }
    // Decimals that leave 4 significant digits, none for large numbers.
    let decimals = usize::try_from((3 - a.log10().floor() as i32).max(0)).unwrap_or(0);
    let text = format!("{value:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

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

/// Median of the finite values of a sample: the middle value, or the mean
/// of the two middle values for an even count; `None` when none is finite.
/// For summaries (history's ranking of parameters).
#[must_use]
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        f64::midpoint(v[n / 2 - 1], v[n / 2])
    })
}

/// Upper median of `values` (the value at index `len / 2` once ordered:
/// for an even count the upper of the two middle values), found in linear
/// time without allocating; reorders `values`. For robust scales in inner
/// loops (the stripe fit's residual median and MAD), where averaging the
/// middle pair buys nothing. NaN sorts last ([`f64::total_cmp`]).
///
/// # Panics
/// On an empty slice.
#[must_use]
pub fn upper_median(values: &mut [f64]) -> f64 {
    let mid = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// The steps of a decade that axes, scale bars and arrow scales use: 1, 2
/// or 5 times a power of ten (the one home of this idea for the report's
/// SVG figures and the workbench's plots).
pub const STEPS_125: [f64; 3] = [1.0, 2.0, 5.0];

/// Relative slack when comparing a step with its bound, so that a bound
/// computed as 0.2 · (1 + 1e-16) still gets the step 0.2.
const STEP_SLACK: f64 = 1e-9;

/// The smallest step of 1, 2 or 5 times a power of ten that is at least
/// `least` (same unit); 1 when `least` is not a positive finite number.
#[must_use]
pub fn step_125_at_least(least: f64) -> f64 {
    if !(least.is_finite() && least > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(least.log10().floor());
    STEPS_125
        .iter()
        .map(|m| m * decade)
        .find(|s| *s >= least * (1.0 - STEP_SLACK))
        .unwrap_or(10.0 * decade)
}

/// The largest step of 1, 2 or 5 times a power of ten at or below `most`
/// (same unit); 1 when `most` is not a positive finite number.
#[must_use]
pub fn step_125_at_most(most: f64) -> f64 {
    if !(most.is_finite() && most > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(most.log10().floor());
    STEPS_125
        .iter()
        .rev()
        .map(|m| m * decade)
        .find(|s| *s <= most * (1.0 + STEP_SLACK))
        .unwrap_or(decade)
}

/// `n` and the noun that fits it: "1 pose", "2 poses" (`many` is the
/// plural, for nouns that do not just add an s).
#[must_use]
pub fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The square root of a variance, `0` for a variance that rounding made
/// negative or `-0.0` (`f64::max(-0.0, 0.0)` may keep the sign, and
/// `sqrt(-0.0)` is `-0.0`, printed "-0.000").
#[must_use]
pub fn sigma_of_variance(variance: f64) -> f64 {
    if variance > 0.0 { variance.sqrt() } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sigma_is_never_negative_zero() {
        for v in [-0.0, 0.0, -1e-30, f64::NAN] {
            let s = sigma_of_variance(v);
            assert!(s == 0.0 && s.is_sign_positive(), "{v}: {s}");
        }
        assert_eq!(format!("{:.3}", sigma_of_variance(-0.0)), "0.000");
        assert_eq!(sigma_of_variance(4.0), 2.0);
    }

    #[test]
    fn approx_keeps_four_significant_digits() {
        assert_eq!(approx(2_578.310_078), "2578");
        assert_eq!(approx(0.015_240_1), "0.01524");
        assert_eq!(approx(38.1), "38.1");
        assert_eq!(approx(-45.0), "-45");
        assert_eq!(approx(1.5e160), "1.500e160");
        assert_eq!(approx(0.0), "0");
    }

    #[test]
    fn plurals() {
        assert_eq!(plural(1, "pose", "poses"), "1 pose");
        assert_eq!(plural(0, "pose", "poses"), "0 poses");
        assert_eq!(plural(2, "station", "stations"), "2 stations");
    }

    #[test]
    fn medians() {
        assert_eq!(median(&[5.0, 1.0, 3.0, 2.0, 4.0]), Some(3.0));
        assert_eq!(median(&[4.0, 1.0, f64::NAN, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[f64::INFINITY]), None);
        let mut v = [5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(upper_median(&mut v), 3.0);
        let mut w = [4.0, 1.0, 3.0, 2.0];
        assert_eq!(upper_median(&mut w), 3.0);
    }

    #[test]
    fn steps_125_both_ways() {
        assert_eq!(step_125_at_least(0.7), 1.0);
        assert_eq!(step_125_at_least(1.3), 2.0);
        assert_eq!(step_125_at_least(0.2 * (1.0 + 1e-15)), 0.2);
        assert_eq!(step_125_at_least(6.0), 10.0);
        assert_eq!(step_125_at_least(-1.0), 1.0);
        assert_eq!(step_125_at_most(7.9), 5.0);
        assert_eq!(step_125_at_most(23.0), 20.0);
        assert_eq!(step_125_at_most(0.3), 0.2);
        assert_eq!(step_125_at_most(f64::NAN), 1.0);
    }
}
