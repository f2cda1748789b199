//! The engine's tests: the paper's method and `ml` on seeded simulated
//! sessions against their truth, the stripe fits and segmentation, the
//! simulator, every file format and import, the real data set.

#[path = "../support/mod.rs"]
mod support;

mod a_posteriori;
mod diameter;
mod fixed_import;
mod fixed_mount;
mod fixed_side;
mod formats;
mod fuzz;
mod held_out;
mod import;
mod ml;
mod paper;
mod plan_progress;
mod pose_files;
mod pose_only;
mod range;
mod range_spread;
mod recheck;
mod recheck_pose_only;
mod realdata;
mod realdata_starts;
mod robot_import;
mod segment;
mod simulate;
mod stripe;
mod volume_plan;
