//! The workbench's tests: egui_kittest drives the real app (no display,
//! no GPU), finds widgets by their labels, clicks, and checks state.
#![cfg(feature = "gui")]

#[path = "../support/mod.rs"]
mod support;

mod check;
mod compensate;
mod flow34;
mod guided;
mod held_out;
mod import_fixed;
mod import_poses;
mod job_end;
mod leftovers34;
mod measure;
mod range;
mod results_rows;
mod save_as;
mod scene;
mod scene_views;
mod tabs;
mod trust;
mod use_exports;
mod views34;
mod workbench;
