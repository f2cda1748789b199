//! The import form is the engine's [`ImportChoices`] itself, edited
//! directly by the Import view ([`super::ui`]) and validated by the
//! engine when it builds the request (as `spherecal import` fills it from
//! its flags); here only what the views add: the preview's row count and
//! the flange-pose conventions' labels.

pub use crate::engine::assemble::choices::{
    HandEyeChoice, ImportChoices, LogKind, ObservationKind, ProfilesKind, no_return,
};
use crate::engine::files::import::FlangeConvention;

/// Rows the preview shows.
pub const PREVIEW_ROWS: usize = 8;

/// The four flange-pose conventions with their labels.
pub const CONVENTIONS: [(FlangeConvention, &str); 4] = [
    (
        FlangeConvention::AbbQuaternion,
        "ABB (x y z mm, quaternion)",
    ),
    (FlangeConvention::KukaAbc, "KUKA (x y z mm, A B C deg)"),
    (FlangeConvention::FanucWpr, "FANUC (x y z mm, W P R deg)"),
    (
        FlangeConvention::UrRotationVector,
        "UR (x y z m, rotation vector rad)",
    ),
];
