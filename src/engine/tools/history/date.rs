//! The date of a calibration: an ISO date (and time) in a session or file
//! name, or a file time, and where it came from.

use std::fmt;
use std::time::{SystemTime, UNIX_EPOCH};

/// A calendar date with an optional time of day (no time zone: a date in a
/// session name is local to the cell, a file time is UTC). Orders
/// chronologically; a date without a time sorts as midnight.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Timestamp {
    /// Year.
    pub year: i32,
    /// Month, 1-12.
    pub month: u32,
    /// Day of the month, 1-31.
    pub day: u32,
    /// Hour, 0-23 (0 without a time).
    pub hour: u32,
    /// Minute, 0-59.
    pub minute: u32,
    /// Second, 0-59.
    pub second: u32,
    /// Whether a time of day was given.
    pub has_time: bool,
}

impl Timestamp {
    /// A date without a time of day; `None` when it is not a calendar date.
    #[must_use]
    pub fn date(year: i32, month: u32, day: u32) -> Option<Self> {
        ((1..=12).contains(&month) && day >= 1 && day <= days_in_month(year, month)).then_some(
            Self {
                year,
                month,
                day,
                hour: 0,
                minute: 0,
                second: 0,
                has_time: false,
            },
        )
    }

    /// The same date at a time of day; `None` when the time is invalid.
    #[must_use]
    pub fn at(self, hour: u32, minute: u32, second: u32) -> Option<Self> {
        (hour < 24 && minute < 60 && second < 60).then_some(Self {
            hour,
            minute,
            second,
            has_time: true,
            ..self
        })
    }

    /// A file time as a UTC date and time; `None` before 1970 or after
    /// 9999 (the calendar is `humantime`'s RFC 3339 formatter).
    #[must_use]
    pub fn from_system_time(t: SystemTime) -> Option<Self> {
        // humantime formats the years 1970..=9999 (it panics outside them).
        const YEAR_10000: u64 = 253_402_300_800;
        let secs = t.duration_since(UNIX_EPOCH).ok()?.as_secs();
        if secs >= YEAR_10000 {
            return None;
        }
        // `YYYY-MM-DDThh:mm:ssZ`
        let text = humantime::format_rfc3339_seconds(t).to_string();
        let field = |range: std::ops::Range<usize>| text.get(range)?.parse::<u32>().ok();
        let year = i32::try_from(field(0..4)?).ok()?;
        Self::date(year, field(5..7)?, field(8..10)?)?.at(
            field(11..13)?,
            field(14..16)?,
            field(17..19)?,
        )
    }
}

impl fmt::Display for Timestamp {
    /// ISO 8601: `2026-11-20`, or `2026-11-20 14:30:00` with a time.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:04}-{:02}-{:02}", self.year, self.month, self.day)?;
        if self.has_time {
            write!(f, " {:02}:{:02}:{:02}", self.hour, self.minute, self.second)?;
        }
        Ok(())
    }
}

pub(super) fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

pub(super) fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Years accepted in a name: a four-digit number outside this range is a
/// serial or part number, not a date.
pub(super) const NAME_YEARS: std::ops::RangeInclusive<i32> = 1900..=2999;

/// The first ISO 8601 date in `text` (`YYYY-MM-DD`, not inside a longer
/// number), with its time of day when `THH:MM[:SS]` follows (a space or
/// `_` may stand for the `T`). Invalid dates (`2026-02-30`) are skipped.
#[must_use]
pub fn date_in_name(text: &str) -> Option<Timestamp> {
    let b = text.as_bytes();
    let digits = |from: usize, n: usize| -> Option<u32> {
        let s = b.get(from..from + n)?;
        s.iter().all(u8::is_ascii_digit).then(|| {
            s.iter()
                .fold(0_u32, |acc, &c| acc * 10 + u32::from(c - b'0'))
        })
    };
    let is_digit_at = |i: usize| b.get(i).is_some_and(u8::is_ascii_digit);
    for i in 0..b.len() {
        if i > 0 && is_digit_at(i - 1) {
            continue;
        }
        let (Some(y), Some(m), Some(d)) = (digits(i, 4), digits(i + 5, 2), digits(i + 8, 2)) else {
            continue;
        };
        if b.get(i + 4) != Some(&b'-') || b.get(i + 7) != Some(&b'-') || is_digit_at(i + 10) {
            continue;
        }
        let Ok(year) = i32::try_from(y) else { continue };
        if !NAME_YEARS.contains(&year) {
            continue;
        }
        let Some(date) = Timestamp::date(year, m, d) else {
            continue;
        };
        let t = i + 10;
        let time = if matches!(b.get(t), Some(b'T' | b' ' | b'_')) {
            match (digits(t + 1, 2), b.get(t + 3), digits(t + 4, 2)) {
                (Some(h), Some(b':'), Some(min)) => {
                    let sec = if b.get(t + 6) == Some(&b':') {
                        digits(t + 7, 2)
                    } else {
                        Some(0)
                    };
                    let end = if b.get(t + 6) == Some(&b':') {
                        t + 9
                    } else {
                        t + 6
                    };
                    sec.filter(|_| !is_digit_at(end))
                        .and_then(|s| date.at(h, min, s))
                }
                _ => None,
            }
        } else {
            None
        };
        return Some(time.unwrap_or(date));
    }
    None
}

/// Where an entry's date came from (see the module docs for the order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DateSource {
    /// An ISO date in the session name (the result's `session`).
    SessionName,
    /// An ISO date in the result's or its session's file name.
    FileName,
    /// The modification time of the session file (UTC).
    SessionModified,
    /// The modification time of the result file (UTC).
    ResultModified,
    /// None of these could be read; the date is 1970-01-01.
    Unknown,
}

impl DateSource {
    /// In words, for tables.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::SessionName => "session name",
            Self::FileName => "file name",
            Self::SessionModified => "session file time",
            Self::ResultModified => "result file time",
            Self::Unknown => "unknown",
        }
    }

    /// Whether the date was written by a person (a name) rather than
    /// taken from the file system, which changes on a copy.
    #[must_use]
    pub fn is_from_name(self) -> bool {
        matches!(self, Self::SessionName | Self::FileName)
    }
}
