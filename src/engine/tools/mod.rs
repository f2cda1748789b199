//! Layer 5, the tools around the method: views and reports of a result,
//! a library of results over time, simulated sessions with their truth,
//! scoring against the truth, and the planner of poses.
//!
//! | unit | holds |
//! |---|---|
//! | [`result_view`] | one view of a result: headline, within-station pairs, roll/pitch/yaw, identifiability marks |
//! | [`report`] | text summary, HTML report with SVG figures, model export |
//! | [`history`] | a library of results, drift over time |
//! | [`simulate`] | simulated sessions and scans with their truth |
//! | [`evaluate`] | scoring against the truth; the method comparison study |
//! | [`plan`] | pose plans and their predicted accuracy, programs to teach them |
//! | [`scene`] | the cell's geometry for the 3-D scene: links, frames, laser fan, stripes |

pub mod result_view;
pub mod report;
pub mod history;
pub mod simulate;
pub mod evaluate;
pub mod plan;
pub mod scene;
