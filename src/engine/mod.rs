//! The headless calibration engine. It never imports egui, eframe or rfd;
//! the command line and the workbench are two thin callers of it.
//!
//! The units are listed in pipeline order; each uses only units above it.
//!
//! | unit | holds |
//! |---|---|
//! | [`geometry`], [`numeric`] | rigid transforms, twists, roll/pitch/yaw; rounding, medians |
//! | [`robot`] | the MDH model, forward kinematics and Jacobians, presets, inverse kinematics |
//! | [`session`] | the in-memory session every function takes |
//! | [`stripe`] | circle fit of a stripe, the sphere centre (eq. 21) |
//! | [`handeye`] | the initial hand-eye (eq. 3-9) |
//! | [`validate`] | ε (eq. 20), statistics, Fig. 5 and 6 distances |
//! | [`solve`] | the loop of Fig. 2 around the paper's update (eq. 10-19) or `ml` |
//! | [`format`] | session and result files, atomic writes |
//! | [`report`] | text summary, HTML report, model export |
//! | [`cell`] | what the simulator and the planner share about a cell |
//! | [`import`] | joint logs and profiles into a session |
//! | [`simulate`], [`plan`], [`history`], [`evaluate`] | simulated sessions, pose plans, drift over time, method comparison |

pub mod cell;
pub mod evaluate;
pub mod format;
pub mod geometry;
pub mod handeye;
pub mod history;
pub mod import;
pub mod numeric;
pub mod plan;
pub mod report;
pub mod result_view;
pub mod robot;
pub mod session;
pub mod simulate;
pub mod solve;
pub mod stripe;
pub mod validate;
