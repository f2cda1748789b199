//! Layer 6, using a calibration: measuring parts into one frame with each
//! point's uncertainty, and driving the robot where it is meant to go.
//!
//! | unit | holds |
//! |---|---|
//! | [`measure`] | scans into base-frame point clouds through a result, each point with its σ; sphere self-validation; PLY, E57, CSV |
//! | [`compensate`] | robot targets and programs compensated through a calibration: IK on the calibrated model, tool data per controller, per-target corrections and flags |
//! | [`check`] | the five-minute re-check: a short scan tested against a result's covariance and noise model, what moved |

pub mod measure;
pub mod compensate;
pub mod check;
