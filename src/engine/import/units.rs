//! Units of the imported files: joint readings (deg or rad) and profile
//! coordinates (mm, µm or m); the session holds deg and mm.

/// Unit of the joint readings in the log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees (the session's unit).
    Deg,
    /// Radians.
    Rad,
}

impl AngleUnit {
    /// The value in degrees.
    #[must_use]
    pub fn to_deg(self, v: f64) -> f64 {
        match self {
            Self::Deg => v,
            Self::Rad => v.to_degrees(),
        }
    }

    /// Short name, `deg` or `rad`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Deg => "deg",
            Self::Rad => "rad",
        }
    }

    /// Parses `deg` or `rad`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "deg" => Some(Self::Deg),
            "rad" => Some(Self::Rad),
            _ => None,
        }
    }
}

/// Unit of the stripe profile coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres (the session's unit).
    Mm,
    /// Micrometres.
    Um,
    /// Metres.
    M,
}

impl LengthUnit {
    /// The value in millimetres.
    #[must_use]
    pub fn to_mm(self, v: f64) -> f64 {
        match self {
            Self::Mm => v,
            Self::Um => v / 1000.0,
            Self::M => v * 1000.0,
        }
    }

    /// Short name, `mm`, `um` or `m` (what [`Self::parse`] reads).
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Um => "um",
            Self::M => "m",
        }
    }

    /// The unit's symbol for people: `mm`, `µm` or `m`.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Um => "µm",
            Self::M => "m",
        }
    }

    /// Parses `mm`, `um` (or `µm`) or `m`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "mm" => Some(Self::Mm),
            "um" | "µm" => Some(Self::Um),
            "m" => Some(Self::M),
            _ => None,
        }
    }
}
