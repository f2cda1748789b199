//! # spherecal
//!
//! Calibrates a robot-mounted laser-stripe sensor against a reference
//! sphere: the hand-eye transform (sensor to flange) and the robot's
//! kinematic errors, by the method of Yang et al. 2014 (see `shared/paper`)
//! and a maximum-likelihood refinement.
//!
//! The [`engine`] is headless; the command line ([`cli`]) and the desktop
//! workbench (`app`, behind the `gui` feature) call the same engine functions.
//!
//! # Conventions
//!
//! - **Frames** (paper eq. 1-2): robot base **B**, flange **E**, sensor **S**.
//!   A point seen by the sensor maps to the base as
//!   `centre_in_base = base_from_flange(q) * flange_from_sensor * centre_in_sensor`.
//!   Transforms are named `target_from_source`; `flange_from_sensor` is the
//!   hand-eye `eT_s`.
//! - **Units**: files hold millimetres and degrees. Inside the engine
//!   lengths are mm and angles are radians, except [`engine::base::robot::Joint`]
//!   and joint readings, which stay in degrees as in the files.
//! - **Numbers**: `f64` throughout.
//! - **The laser plane** is the sensor's `x = 0` plane; stripe points are
//!   `[y, z]` in it. The sphere centre is at `(side·sqrt(R² − r²), y_c, z_c)`
//!   (paper eq. 21).
//! - **Kinematic parameter vector**: `5·n` numbers, joint by joint, in the
//!   order alpha, a, beta, theta, d (rad, mm); link transform
//!   `Rx(alpha)·Tx(a)·Ry(beta)·Rz(q + theta)·Tz(d)` (FORMAT.md).
//! - **Twists** (differential motions, paper eq. 13-16): `[Δx, Δy, Δz, δx, δy, δz]`,
//!   translation first; a point `X` moves by `Δ + δ × X`; the rigid motion of
//!   a twist is [`engine::base::geometry::isometry_from_twist`].
//! - **Hand-eye perturbation**: an update of the hand-eye is a right twist
//!   in the sensor frame, `eT_s ← eT_s · exp(ΔX)`; the unknowns of both
//!   methods are these 6 numbers followed by the `5·n` kinematic errors
//!   ([`engine::calibrate::solve::estimate`]). Hand-eye σs and correlations in a
//!   result refer to these directions.
//! - **Roll, pitch, yaw** (degrees, wherever a rotation is shown: workbench,
//!   report, history, model export): `R = Rz(yaw) · Ry(pitch) · Rx(roll)`,
//!   pitch in [−90°, 90°] ([`engine::base::geometry::roll_pitch_yaw_deg`] and its
//!   inverse [`engine::base::geometry::rotation_from_rpy_deg`]).
//! - **Angles shown** are wrapped to (−180°, 180°]
//!   ([`engine::base::geometry::wrap_deg`]).

pub mod cli;
pub mod engine;

#[cfg(feature = "gui")]
pub mod app;

#[cfg(feature = "gui")]
pub mod screenshots;

/// The demo session embedded in the binary (`sessions/demo-irb2400.json`):
/// what the workbench opens when started without a file.
pub const DEMO_SESSION_JSON: &str = include_str!("../sessions/demo-irb2400.json");

/// File name shown for the embedded demo session.
pub const DEMO_SESSION_NAME: &str = "demo-irb2400.json";
