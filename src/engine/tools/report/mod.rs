//! What people and other tools read of a calibration: the command line's
//! text summary, the self-contained HTML report with its SVG figures, and
//! the calibrated model as JSON, MDH CSV or URDF, the plots on one
//! sheet for print, and the centres and distance errors as CSV tables.

pub mod html;
pub mod model;
pub mod sheet;
pub mod summary;
pub mod svg;
pub mod tables;
pub mod tool_data;
pub mod ur_calibration;
pub mod urdf_back;
