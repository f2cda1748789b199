//! Writes the example history library of `sessions/history/` (run by
//! `sessions/history/make.sh`): five dated calibrations of one simulated
//! ABB IRB 2400/16 whose sensor reports sphere centres, about a month
//! apart (9 identify and 4 validate stations of 4 poses each, `ml` at its
//! defaults).
//!
//! - January to March: the same robot and sensor (the paper's Table 1
//!   errors and hand-eye), each month with new poses and new noise (seeds
//!   1-3): repeats, no jump expected.
//! - April: the sensor was knocked and remounted. It now sits
//!   [`SENSOR_SHIFT_MM`] further along its own y axis, so the true hand-eye
//!   is `eT_s · Trans(0, 0.4, 0)`: a hand-eye jump.
//! - May: the axis-3 motor was replaced and its zero moved by
//!   [`JOINT3_ZERO_SHIFT_DEG`]: a jump of `theta3` (the sensor stays where
//!   April left it).
//!
//! The simulator has no option for either change, so both are applied to
//! the simulated session the way they happen in a cell: a sensor that sits
//! further along its y axis sees every centre that much lower in y; a joint
//! whose zero moved by Δ reads Δ less at the same physical angle, which the
//! calibrated model shows as `theta3 + Δ`.
//!
//! Usage: `cargo run --no-default-features --example history_library -- [FOLDER]`
//! (default `sessions/history`).

use std::path::PathBuf;

use anyhow::Context as _;
use nalgebra::Vector3;
use spherecal::engine::base::session::{Observation, Session};
use spherecal::engine::calibrate::solve::{self, Options};
use spherecal::engine::files::format;
use spherecal::engine::tools::simulate::{self, SimConfig};

/// Sensor displacement along its own y axis after the April remount, mm:
/// large against the ~0.013 mm σ `ml` reports for the hand-eye x and y
/// in these sessions, small against anything a technician would notice.
const SENSOR_SHIFT_MM: f64 = 0.4;
/// Change of the joint-3 zero after the May motor swap, deg: about 7
/// combined σ of `theta3` in these sessions (σ ≈ 0.015° each).
const JOINT3_ZERO_SHIFT_DEG: f64 = 0.15;

/// One month of the library.
struct Month {
    date: &'static str,
    seed: u64,
    remark: &'static str,
    sensor_shift: f64,
    joint3_shift: f64,
}

const MONTHS: [Month; 5] = [
    Month {
        date: "2026-01-12",
        seed: 1,
        remark: "",
        sensor_shift: 0.0,
        joint3_shift: 0.0,
    },
    Month {
        date: "2026-02-09",
        seed: 2,
        remark: "",
        sensor_shift: 0.0,
        joint3_shift: 0.0,
    },
    Month {
        date: "2026-03-09",
        seed: 3,
        remark: "",
        sensor_shift: 0.0,
        joint3_shift: 0.0,
    },
    Month {
        date: "2026-04-13",
        seed: 4,
        remark: " (sensor remounted)",
        sensor_shift: SENSOR_SHIFT_MM,
        joint3_shift: 0.0,
    },
    Month {
        date: "2026-05-11",
        seed: 5,
        remark: " (axis 3 motor replaced)",
        sensor_shift: SENSOR_SHIFT_MM,
        joint3_shift: JOINT3_ZERO_SHIFT_DEG,
    },
];

/// The session a sensor moved by `shift` (sensor frame, mm) would record:
/// the true hand-eye becomes `eT_s · Trans(shift)`, so every centre is
/// seen at `c − shift`. Stripes can only move within the laser plane.
fn shift_sensor(session: &mut Session, shift: Vector3<f64>) -> anyhow::Result<()> {
    for m in &mut session.measurements {
        match &mut m.observation {
            Observation::Centre(c) => *c = (*c - shift).map(|x| (x * 1e6).round() / 1e6),
            Observation::Stripe(points) => {
                anyhow::ensure!(
                    shift.x == 0.0,
                    "a stripe cannot move out of the laser plane"
                );
                for p in points {
                    p[0] = ((p[0] - shift.y) * 1e6).round() / 1e6;
                    p[1] = ((p[1] - shift.z) * 1e6).round() / 1e6;
                }
            }
        }
    }
    Ok(())
}

/// The session a robot whose joint `joint` (0-based) zero moved by `delta`
/// (deg) would record: every reading of that joint is `delta` smaller.
fn move_joint_zero(session: &mut Session, joint: usize, delta: f64) {
    for m in &mut session.measurements {
        if let Some(q) = m.joints.get_mut(joint) {
            *q = ((*q - delta) * 1e9).round() / 1e9;
        }
    }
}

fn main() -> anyhow::Result<()> {
    let folder = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "sessions/history".into()),
    );
    std::fs::create_dir_all(&folder).with_context(|| folder.display().to_string())?;
    for m in &MONTHS {
        let name = format!("IRB 2400 cell 3, {}{}", m.date, m.remark);
        let config = SimConfig {
            seed: m.seed,
            name: Some(name.clone()),
            centres: true,
            n_identify: 9,
            n_validate: 4,
            poses_per_station: 4,
            ..SimConfig::default()
        };
        let (mut s, _truth) = simulate::simulate(&config)?;
        if m.sensor_shift != 0.0 {
            shift_sensor(&mut s, Vector3::new(0.0, m.sensor_shift, 0.0))?;
        }
        if m.joint3_shift != 0.0 {
            move_joint_zero(&mut s, 2, m.joint3_shift);
        }
        let stem = format!("cell3-{}", m.date);
        let session_path = folder.join(format!("{stem}.json"));
        let result_path = folder.join(format!("{stem}.result.json"));
        format::save_session(&s, &session_path)?;
        // Calibrate what the file holds, exactly as `spherecal calibrate` does.
        let s = format::load_session(&session_path)?;
        let (_, cal) = solve::calibrate(&s, &Options::from_session(&s))
            .with_context(|| session_path.display().to_string())?;
        format::save_result(
            &format::ResultFile::from_calibration(&s, &cal),
            &result_path,
        )?;
        println!(
            "{}: validation std {:.4} mm -> {}",
            name,
            cal.validation.as_ref().map_or(f64::NAN, |v| v.after.std),
            result_path.display()
        );
    }
    Ok(())
}
