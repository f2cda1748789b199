//! The headless calibration engine. It never imports egui, eframe or rfd;
//! the command line and the workbench are two thin callers of it.
//!
//! Where each part of the paper lives:
//!
//! | paper | module |
//! |---|---|
//! | eq. 1-2 (frames), MDH model, `J_i` of eq. 16 | [`kinematics`] |
//! | eq. 21 (sphere centre from a stripe circle) | [`stripe`] |
//! | eq. 3-9 (initial hand-eye) | [`handeye`] |
//! | eq. 10-19 (joint identification, truncated SVD) | [`identify`] |
//! | eq. 20 (ε) and the validation of section 4.3 | [`validate`] |
//! | Fig. 2 (the loop) and the whole pipeline | [`calibrate`] |

pub mod calibrate;
pub mod error;
pub mod evaluate;
pub mod geometry;
pub mod handeye;
pub mod history;
pub mod html_report;
pub mod identify;
pub mod ik;
pub mod import;
pub mod kinematics;
pub mod ml;
pub mod model;
pub mod model_export;
pub mod plan;
pub mod report;
pub mod session;
pub mod simulate;
pub mod stripe;
pub mod svg;
pub mod validate;
