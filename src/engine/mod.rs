//! The headless calibration engine. It never imports egui, eframe or rfd;
//! the command line and the workbench are two thin callers of it.
//!
//! The units are listed in pipeline order; each uses only units above it.
//!
//! | unit | holds |
//! |---|---|
//! | [`geometry`], [`numeric`] | rigid transforms, twists, roll/pitch/yaw; rounding, medians |
//! | [`robot`] | the MDH model, forward kinematics and Jacobians (eq. 1-2, 16), presets, inverse kinematics |
//! | [`session`] | the in-memory session every function takes, its rules, leaving measurements out |
//! | [`stripe`] | circle fit of a stripe, the sphere centre (eq. 21) |
//! | [`handeye`] | the initial hand-eye (eq. 3-9) |
//! | [`validate`] | ε (eq. 20), statistics, Fig. 5 and 6 distances |
//! | [`solve`] | prepare (each stripe fitted once), the one loop of Fig. 2 around a step: the paper's update (eq. 10-19) or `ml`'s |
//! | [`format`](mod@format) | session and result files (typed both ways), JSON text, atomic writes |
//! | [`result_view`] | one view of a result: headline, within-station pairs, roll/pitch/yaw, identifiability marks |
//! | [`report`] | text summary, HTML report with SVG figures, model export |
//! | [`cell`] | what the simulator and the planner share about a cell: sensor, workspace, approach cones, joint logs, seeded streams |
//! | [`import`] | joint logs and profiles into a session |
//! | [`measure`] | scans into base-frame point clouds through a result, each point with its σ; sphere self-validation; PLY, E57, CSV |
//! | [`simulate`] | simulated sessions with their truth |
//! | [`evaluate`] | scoring against the truth; the method comparison study |
//! | [`plan`] | pose plans and their predicted accuracy |
//! | [`history`] | a library of results, drift over time |
//! | [`compensate`] | robot targets and programs compensated through a calibration: IK on the calibrated model, tool data per controller, per-target corrections and flags |

pub mod cell;
pub mod compensate;
pub mod evaluate;
pub mod format;
pub mod geometry;
pub mod handeye;
pub mod history;
pub mod import;
pub mod measure;
pub mod numeric;
pub mod plan;
pub mod program;
pub mod report;
pub mod result_view;
pub mod robot;
pub mod session;
pub mod simulate;
pub mod solve;
pub mod stripe;
pub mod table;
pub mod validate;
