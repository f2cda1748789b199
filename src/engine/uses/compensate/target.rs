//! One target: the pose wanted, its branch, the calibrated solution, the
//! pose to command, the configuration, the flags; and the numbers written
//! back in the file's own style.
//!
//! **Numbers written.** Tables and JSON lists get full precision (the
//! shortest text that reads back to the same `f64`; a value that did not
//! change keeps its text). Programs keep each number's style (its
//! decimals, leading zero, sign, FANUC's column width) with at least the
//! decimals the compensation needs: 3 for mm (0.5 µm), 4 for deg (KUKA's
//! `A B C`, joints), 3 for FANUC's `W P R` as FANUC writes them (≤ 9 µrad),
//! 7 for an ABB quaternion, 6 for UR's m and rad. Rotations are written
//! nearest the numbers they replace (a quaternion keeps its sign, Euler
//! angles their turn, a rotation vector its side of π), so a small
//! correction changes the numbers by a little.

use std::f64::consts::PI;

use nalgebra::Vector3;

use super::config::{self, Vendor};
use super::{Flag, JointTargets, Model, Options, TargetFailure, TargetReport};
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::robot::ik::DOF;
use crate::engine::files::program::style::{NumberStyle, full_precision};
use crate::engine::files::program::{PoseFile, PoseFormat, TargetValue};

/// The controller whose configuration fields a layout writes.
fn vendor(format: PoseFormat) -> Option<Vendor> {
    match format {
        PoseFormat::Rapid => Some(Vendor::Abb),
        PoseFormat::Krl => Some(Vendor::Kuka),
        PoseFormat::FanucLs => Some(Vendor::Fanuc),
        _ => None,
    }
}

/// The flags of a target: far in joint space from every identify pose
/// (deg), outside the region the calibration saw (mm), or a predicted σ
/// above the tolerance (mm).
fn flags_of(
    options: &Options,
    nearest_identify_deg: Option<f64>,
    outside_mm: f64,
    sigma_mm: Option<f64>,
) -> Vec<Flag> {
    let mut flags = Vec::new();
    if let Some(d) = nearest_identify_deg
        && d > options.far_joints_deg
    {
        flags.push(Flag::FarInJoints(d, options.far_joints_deg));
    }
    if outside_mm > options.region_margin_mm {
        flags.push(Flag::OutsideRegion(outside_mm, options.region_margin_mm));
    }
    if let Some(s) = sigma_mm
        && s > options.sigma_tolerance_mm
    {
        flags.push(Flag::Uncertain(s, options.sigma_tolerance_mm));
    }
    flags
}

/// Compensates target `index` of `file`.
pub(super) fn compensate_target(
    model: &Model,
    file: &PoseFile,
    index: usize,
    options: &Options,
) -> Result<TargetReport, TargetFailure> {
    let t = &file.targets[index];
    let fail = |message: String| TargetFailure {
        name: t.name.clone(),
        line: t.line,
        message,
    };
    let arms = &model.arms;
    let tool = model.tool;
    let mut notes = Vec::new();
    let mut config_update = None;
    let (joints_target, written, qn, qc, branch, wanted, values) = match &t.value {
        TargetValue::Pose { values, convention } => {
            let wanted = convention
                .pose_from_values(values)
                .map_err(|e| fail(e.to_string()))?;
            let flange = wanted * tool.inverse();
            let range = t.config.as_ref().map(|(_, r)| r.clone());
            let written_text = range.map(|r| file.text[r].to_string());
            let written_config = vendor(file.format)
                .zip(written_text.as_deref())
                .and_then(|(v, text)| v.parse(text).map(|c| (v, c)));
            let (qn, branch) = arms
                .nominal_branch(&flange, written_config)
                .ok_or_else(|| {
                    fail("out of reach: the nominal model has no joint solution for it".to_string())
                })?;
            let qc = arms
                .calibrated_solution(&flange, &qn)
                .map_err(|e| fail(e.describe()))?;
            let commanded = arms.nominal.base_from_flange(&qc) * tool;
            let new = nearest(
                *convention,
                &convention.values_from_pose(&commanded),
                values,
            );
            if let (Some(text), Some(v)) = (&written_text, vendor(file.format)) {
                match written_config {
                    Some((_, written)) => {
                        let of_n = v.config(&qn, config::posture(&arms.nominal, &qn));
                        let of_c = v.config(&qc, config::posture(&arms.nominal, &qc));
                        if written == of_n && of_c != of_n {
                            let new_text = config::render(&of_c, text);
                            notes.push(format!(
                                "configuration {} updated to {}: the calibrated solution lies across one of its boundaries",
                                text.trim(),
                                new_text.trim()
                            ));
                            config_update = Some((text.clone(), new_text));
                        } else if written != of_n {
                            notes.push(format!(
                                "configuration {} is not that of the solution used ({of_n}, spherecal's reading of the controller's fields): kept as written; branch by {}",
                                text.trim(),
                                branch.describe()
                            ));
                        }
                    }
                    None => notes.push(format!(
                        "configuration `{}` not read: kept as written",
                        text.trim()
                    )),
                }
            }
            if matches!(branch, super::arms::BranchRule::ConfigurationElsewhere(_)) {
                notes.push(format!("branch by {}", branch.describe()));
            }
            (false, true, qn, qc, branch, wanted, new)
        }
        TargetValue::Joints { deg, radians } => {
            let qw: [f64; DOF] = deg.as_slice().try_into().map_err(|_| {
                fail(format!(
                    "{} joint values, the robot has {DOF} joints",
                    deg.len()
                ))
            })?;
            let flange = arms.nominal.base_from_flange(&qw);
            let wanted = flange * tool;
            let mut keep = options.joint_targets == JointTargets::Keep;
            let qc = if keep {
                qw
            } else {
                // A joint target with no calibrated solution on its branch
                // (a home position at a wrist singularity, all joints 0) is
                // a place to park, not a pose to measure at: kept as
                // written, with a note, rather than refusing the program.
                match arms.calibrated_solution(&flange, &qw) {
                    Ok(q) => q,
                    Err(e) => {
                        keep = true;
                        notes.push(format!("a joint target kept as written: {}", e.describe()));
                        qw
                    }
                }
            };
            let new: Vec<f64> = qc
                .iter()
                .map(|v| if *radians { v.to_radians() } else { *v })
                .collect();
            (
                true,
                !keep,
                qw,
                qc,
                super::arms::BranchRule::Joints,
                wanted,
                new,
            )
        }
    };
    let commanded = arms.nominal.base_from_flange(&qc) * tool;
    let correction_mm = (commanded.translation.vector - wanted.translation.vector).norm();
    let correction_deg = commanded.rotation.angle_to(&wanted.rotation).to_degrees();
    let joint_change_deg = qc
        .iter()
        .zip(&qn)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let sigma_mm = model.predictor.as_ref().map(|p| p.sigma(&qc));
    let nearest_identify_deg = model.region.nearest_identify(&qc);
    let outside_mm = model.region.outside(&wanted);
    let flags = flags_of(options, nearest_identify_deg, outside_mm, sigma_mm);
    if joints_target && !written && options.joint_targets == JointTargets::Keep {
        notes.push("a joint target, kept as written (--joint-targets keep)".to_string());
    }
    Ok(TargetReport {
        index,
        name: t.name.clone(),
        line: t.line,
        joints_target,
        written,
        nominal_joints: qn,
        joints: qc,
        branch,
        wanted,
        commanded,
        correction_mm,
        correction_deg,
        joint_change_deg,
        sigma_mm,
        nearest_identify_deg,
        outside_mm,
        flags,
        values,
        config_update,
        notes,
    })
}

/// `new` (a pose's values in `convention`, its encoding: an ABB
/// quaternion with `w ≥ 0`) moved to the representation nearest `old`, so
/// that a rewritten target changes by its correction only: the
/// quaternion's sign as the target had it, Euler angles by whole turns, a
/// rotation vector to its equivalent on the other side of π.
pub(super) fn nearest(convention: FlangeConvention, new: &[f64], old: &[f64]) -> Vec<f64> {
    let mut v = new.to_vec();
    match convention {
        FlangeConvention::AbbQuaternion => {
            let dot: f64 = (3..7).map(|k| v[k] * old[k]).sum();
            if dot < 0.0 {
                for x in &mut v[3..7] {
                    *x = -*x;
                }
            }
        }
        FlangeConvention::KukaAbc | FlangeConvention::FanucWpr => {
            for k in 3..6 {
                v[k] += 360.0 * ((old[k] - v[k]) / 360.0).round();
            }
        }
        FlangeConvention::UrRotationVector => {
            let r = Vector3::new(v[3], v[4], v[5]);
            let angle = r.norm();
            if angle > 0.0 {
                let other = r * ((angle - 2.0 * PI) / angle);
                let o = Vector3::new(old[3], old[4], old[5]);
                if (other - o).norm() < (r - o).norm() {
                    v[3..6].copy_from_slice(other.as_slice());
                }
            }
        }
        FlangeConvention::Matrix => {}
    }
    v
}

/// Least decimals a number of `value` at place `k` needs (module doc).
fn min_decimals(value: &TargetValue, k: usize) -> usize {
    match value {
        TargetValue::Joints { radians: true, .. } => 6,
        TargetValue::Joints { radians: false, .. } => 4,
        TargetValue::Pose { convention, .. } => match (convention, k < 3) {
            (FlangeConvention::UrRotationVector, _) => 6,
            (FlangeConvention::AbbQuaternion, false) | (FlangeConvention::Matrix, _) => 7,
            (FlangeConvention::FanucWpr, false) | (_, true) => 3,
            (FlangeConvention::KukaAbc, false) => 4,
        },
    }
}

/// The numbers of a compensated target as written into `file`.
pub(super) fn written_numbers(file: &PoseFile, report: &TargetReport) -> Vec<String> {
    let t = &file.targets[report.index];
    t.spans
        .iter()
        .zip(&report.values)
        .enumerate()
        .map(|(k, (span, v))| {
            let original = &file.text[span.clone()];
            match file.format {
                PoseFormat::Table | PoseFormat::Json => full_precision(original, *v),
                f => NumberStyle::of(original).write(
                    *v,
                    min_decimals(&t.value, k),
                    f == PoseFormat::FanucLs,
                ),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_are_written_nearest_the_old_numbers() {
        let q = nearest(
            FlangeConvention::AbbQuaternion,
            &[0.0, 0.0, 0.0, -0.5, -0.5, 0.5, 0.5],
            &[0.0, 0.0, 0.0, 0.5, 0.5, -0.5, -0.5],
        );
        assert_eq!(q[3..], [0.5, 0.5, -0.5, -0.5]);
        let k = nearest(
            FlangeConvention::KukaAbc,
            &[0.0, 0.0, 0.0, 179.9, 0.0, -179.8],
            &[0.0, 0.0, 0.0, -179.9, 0.0, 179.9],
        );
        assert!((k[3] + 180.1).abs() < 1e-9 && (k[5] - 180.2).abs() < 1e-9);
        let ur = nearest(
            FlangeConvention::UrRotationVector,
            &[0.0, 0.0, 0.0, PI - 0.01, 0.0, 0.0],
            &[0.0, 0.0, 0.0, -(PI - 0.005), 0.0, 0.0],
        );
        assert!((ur[3] + PI + 0.01).abs() < 1e-12, "{ur:?}");
    }
}
