//! Writing a number back into a robot program in the style of the number
//! it replaces: as many decimals (never fewer than the quantity needs), a
//! leading zero or not (`-.858`), an explicit `+` or not, and, where a
//! layout aligns its columns (FANUC's `/POS`), the same width.

/// How one number of a file is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumberStyle {
    /// Digits after the point (0 for `12`).
    pub decimals: usize,
    /// Whether a magnitude below 1 has its `0` before the point.
    pub leading_zero: bool,
    /// Whether a positive number has an explicit `+`.
    pub plus: bool,
    /// Characters it takes.
    pub width: usize,
}

impl NumberStyle {
    /// The style of `text` as written (`-0.060`, `.5`, `+12`, `1.5e-3`;
    /// an exponent counts its mantissa's decimals).
    #[must_use]
    pub fn of(text: &str) -> Self {
        let t = text.trim();
        let mantissa = t.split(['e', 'E']).next().unwrap_or(t);
        let unsigned = mantissa.trim_start_matches(['+', '-']);
        let decimals = unsigned.split_once('.').map_or(0, |(_, f)| f.len());
        Self {
            decimals,
            leading_zero: !unsigned.starts_with('.'),
            plus: mantissa.starts_with('+'),
            width: t.len(),
        }
    }

    /// `value` in this style with at least `min_decimals` decimals; padded
    /// with spaces on the left to [`Self::width`] when `keep_width` and it
    /// is shorter. A value that rounds to zero is written without a sign.
    #[must_use]
    pub fn write(&self, value: f64, min_decimals: usize, keep_width: bool) -> String {
        let decimals = self.decimals.max(min_decimals);
        let mut body = format!("{:.*}", decimals, value.abs());
        let zero = body.bytes().all(|b| b == b'0' || b == b'.');
        if !self.leading_zero && body.starts_with("0.") {
            body.remove(0);
        }
        let sign = if value < 0.0 && !zero {
            "-"
        } else if self.plus {
            "+"
        } else {
            ""
        };
        let out = format!("{sign}{body}");
        if keep_width && out.len() < self.width {
            format!("{}{out}", " ".repeat(self.width - out.len()))
        } else {
            out
        }
    }
}

/// `value` written in full precision (the shortest text that reads back
/// to the same `f64`), unless it equals `original`'s value, whose text is
/// then kept as it was: the writing of tables and JSON pose lists. An
/// original with a decimal comma (`1000,5`: a table cell, never JSON)
/// gets one too.
#[must_use]
pub fn full_precision(original: &str, value: f64) -> String {
    let comma = original.contains(',');
    let read = if comma {
        original.trim().replacen(',', ".", 1).parse::<f64>().ok()
    } else {
        original.trim().parse::<f64>().ok()
    };
    if read == Some(value) {
        original.to_string()
    } else if comma {
        format!("{value}").replacen('.', ",", 1)
    } else {
        format!("{value}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn styles_are_read_and_kept() {
        let s = NumberStyle::of("-.858");
        assert_eq!((s.decimals, s.leading_zero, s.plus), (3, false, false));
        assert_eq!(s.write(0.25, 0, false), ".250");
        assert_eq!(s.write(-0.25, 4, false), "-.2500");
        assert_eq!(NumberStyle::of("+12").write(3.4, 0, false), "+3");
        assert_eq!(NumberStyle::of("1.5e-3").decimals, 1);
        // FANUC columns keep their width; a longer number is not cut.
        let f = NumberStyle::of("-177.000");
        assert_eq!(f.write(9.5, 3, true), "   9.500");
        assert_eq!(f.write(-1177.25, 3, true), "-1177.250");
        // No negative zero.
        assert_eq!(NumberStyle::of("1.00").write(-0.0004, 2, false), "0.00");
    }

    #[test]
    fn full_precision_keeps_equal_values() {
        assert_eq!(full_precision("0.0", 0.0), "0.0");
        assert_eq!(
            full_precision("1", 1.0000000000000002),
            "1.0000000000000002"
        );
        let v = 412.123_456_789_012_3_f64;
        assert_eq!(full_precision("412.1", v).parse::<f64>().unwrap(), v);
        // A decimal comma is kept, and written again.
        assert_eq!(full_precision("1000,5", 1000.5), "1000,5");
        assert_eq!(full_precision("1000,5", 1000.75), "1000,75");
        assert_eq!(full_precision("-1,0", -2.0), "-2");
    }
}
