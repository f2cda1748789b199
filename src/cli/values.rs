//! How the command line reads a flag's value, so that a bad value is
//! refused by clap before any work, naming the flag, the value as typed
//! (never a number of 309 digits) and the unit: keywords whose list comes
//! from the engine (shown in `--help` as the possible values, with the
//! engine's own description of each), and numbers with their range and
//! unit.

use std::ffi::OsStr;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

/// A keyword flag: the engine's keys (each with an optional description)
/// and the engine's parser, which may also take aliases (`ABB` for `abb`,
/// `ls` for `fanuc-ls`). `--help` lists the keys; a value the parser
/// refuses gets clap's message with the keys and a suggestion.
#[derive(Clone)]
pub struct Keywords<T> {
    keys: Vec<(&'static str, Option<&'static str>)>,
    parse: fn(&str) -> Option<T>,
}

impl<T> Keywords<T> {
    /// The keys (in the order help lists them) and the parser.
    #[must_use]
    pub fn new(
        keys: Vec<(&'static str, Option<&'static str>)>,
        parse: fn(&str) -> Option<T>,
    ) -> Self {
        Self { keys, parse }
    }

    /// The keys, without descriptions.
    #[must_use]
    pub fn plain(
        keys: impl IntoIterator<Item = &'static str>,
        parse: fn(&str) -> Option<T>,
    ) -> Self {
        Self::new(keys.into_iter().map(|k| (k, None)).collect(), parse)
    }
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Keywords<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        if let Some(parsed) = value.to_str().and_then(|s| (self.parse)(s.trim())) {
            return Ok(parsed);
        }
        // Not a key nor an alias: clap's own message, listing the keys.
        let keys: Vec<&'static str> = self.keys.iter().map(|(k, _)| *k).collect();
        let refused = PossibleValuesParser::new(keys).parse_ref(cmd, arg, value);
        Err(refused.err().unwrap_or_else(|| {
            clap::Error::raw(
                clap::error::ErrorKind::InvalidValue,
                format!("`{}` is not understood\n", value.to_string_lossy()),
            )
        }))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.keys.iter().map(|(key, help)| {
            let value = PossibleValue::new(*key);
            match help {
                Some(h) => value.help(*h),
                None => value,
            }
        })))
    }
}

/// The range a number flag takes: finite, above `min` (or at it when
/// `min_included`), at most `max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    min: f64,
    min_included: bool,
    max: Option<(f64, bool)>,
    unit: &'static str,
}

impl Range {
    /// Any finite number ≥ 0, in `unit`.
    #[must_use]
    pub fn non_negative(unit: &'static str) -> Self {
        Self {
            min: 0.0,
            min_included: true,
            max: None,
            unit,
        }
    }

    /// Any finite number > 0, in `unit`.
    #[must_use]
    pub fn positive(unit: &'static str) -> Self {
        Self {
            min_included: false,
            ..Self::non_negative(unit)
        }
    }

    /// A number strictly between 0 and 1 (a relative tolerance).
    #[must_use]
    pub fn fraction_open() -> Self {
        Self {
            max: Some((1.0, false)),
            ..Self::positive("")
        }
    }

    /// A number from 0 to 1, both included (a fraction).
    #[must_use]
    pub fn fraction() -> Self {
        Self {
            max: Some((1.0, true)),
            ..Self::non_negative("")
        }
    }

    /// This range, up to `max` included.
    #[must_use]
    pub fn at_most(self, max: f64) -> Self {
        Self {
            max: Some((max, true)),
            ..self
        }
    }

    /// Whether `v` is in the range.
    #[must_use]
    pub fn contains(&self, v: f64) -> bool {
        let above = if self.min_included {
            v >= self.min
        } else {
            v > self.min
        };
        let below = match self.max {
            None => true,
            Some((m, true)) => v <= m,
            Some((m, false)) => v < m,
        };
        v.is_finite() && above && below
    }

    /// The rule in words: "a number of mm ≥ 0", "a number in (0, 1)",
    /// "a number of mm from 0 to 10".
    #[must_use]
    pub fn describe(&self) -> String {
        let show = crate::engine::base::numeric::show;
        let of = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" of {}", self.unit)
        };
        match self.max {
            None => format!(
                "a number{of} {} {}",
                if self.min_included { "≥" } else { ">" },
                show(self.min)
            ),
            Some((max, true)) if self.min_included => {
                format!("a number{of} from {} to {}", show(self.min), show(max))
            }
            Some((max, max_included)) => format!(
                "a number{of} in {}{}, {}{}",
                if self.min_included { "[" } else { "(" },
                show(self.min),
                show(max),
                if max_included { "]" } else { ")" }
            ),
        }
    }

    /// Parses a value of this range; the error says what was expected.
    ///
    /// # Errors
    /// Not a number, not finite, or outside the range.
    pub fn parse(&self, s: &str) -> Result<f64, String> {
        match s.trim().parse::<f64>() {
            Ok(v) if self.contains(v) => Ok(v),
            _ => Err(format!("expected {}", self.describe())),
        }
    }
}

/// A number flag's parser of `range` (for `value_parser = …`).
pub fn number(
    range: Range,
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |s: &str| range.parse(s)
}

/// A count flag's parser: a whole number from `min` to `max`.
pub fn count<N>(
    min: N,
    max: N,
) -> impl Fn(&str) -> Result<N, String> + Clone + Send + Sync + 'static
where
    N: std::str::FromStr + PartialOrd + std::fmt::Display + Copy + Send + Sync + 'static,
{
    move |s: &str| match s.trim().parse::<N>() {
        Ok(n) if min <= n && n <= max => Ok(n),
        _ => Err(format!("expected a whole number from {min} to {max}")),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn ranges_take_what_they_say_and_name_the_unit() {
        let noise = Range::non_negative("mm").at_most(10.0);
        assert_eq!(noise.parse("0").unwrap(), 0.0);
        assert_eq!(noise.parse("10").unwrap(), 10.0);
        for bad in ["-1", "10.5", "nan", "inf", "1e308", "x"] {
            assert_eq!(
                noise.parse(bad).unwrap_err(),
                "expected a number of mm from 0 to 10",
                "{bad}"
            );
        }
        assert_eq!(
            Range::fraction_open().parse("1").unwrap_err(),
            "expected a number in (0, 1)"
        );
        assert_eq!(Range::fraction_open().parse("1e-7").unwrap(), 1e-7);
        assert_eq!(
            Range::positive("deg").parse("0").unwrap_err(),
            "expected a number of deg > 0"
        );
        assert_eq!(Range::fraction().describe(), "a number from 0 to 1");
        assert_eq!(
            Range::positive("mm").at_most(1000.0).describe(),
            "a number of mm in (0, 1000]"
        );
        assert_eq!(
            count(1, 5)("0").unwrap_err(),
            "expected a whole number from 1 to 5"
        );
        assert_eq!(count(1, 5)("5").unwrap(), 5);
    }
}
