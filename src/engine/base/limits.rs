//! Physical plausibility limits of a session's numbers. Values beyond them
//! are not a sphere calibration of an industrial robot (and, far enough
//! out, overflow every computation); the loader refuses them by name.

/// Largest sphere diameter, mm.
pub const SPHERE_DIAMETER_MM: f64 = 1000.0;
/// Largest |coordinate| of a stripe point or a given centre (sensor
/// frame), mm.
pub const SENSOR_COORDINATE_MM: f64 = 10_000.0;
/// Largest |translation| of a transform (hand-eye, base, flange, a
/// flange pose) and largest MDH length `a`, `d`, mm.
pub const LENGTH_MM: f64 = 100_000.0;
/// Largest |angle| of a joint reading or an MDH angle, deg (100 turns).
pub const ANGLE_DEG: f64 = 36_000.0;
/// Largest reference distance, mm.
pub const DISTANCE_MM: f64 = 100_000.0;
/// Largest `solver.threshold`, mm.
pub const THRESHOLD_MM: f64 = 1000.0;
/// Largest `solver.max_iterations`.
pub const MAX_ITERATIONS: f64 = 1_000_000.0;
