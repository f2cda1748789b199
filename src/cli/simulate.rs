//! `spherecal simulate` (in progress).
