//! The two models of one arm, nominal (what the controller runs) and
//! calibrated (what the robot is), prepared for inverse kinematics: every
//! nominal solution of a flange pose, the branch a target means, and the
//! calibrated solution on that branch, by Newton from the nominal one
//! (the calibrated model differs by tenths of a degree and millimetre, so
//! the step stays in the branch's basin).
//!
//! **Which branch.** Of the nominal solutions, those within the joint
//! limits (widened by [`MAX_BRANCH_CHANGE_DEG`]) count, unless none is.
//! A target that names its configuration (RAPID `cf`,
//! KUKA `S`/`T`, FANUC `CONFIG`) takes the solution with that
//! configuration ([`super::config`]). A target without one, or whose
//! configuration no solution has, takes
//!
//! 1. the solution nearest (in joint space) to one of the poses the
//!    calibration saw (the result's `pose_joints`, or the session's):
//!    the branch the calibration saw;
//! 2. else the branch a cell teaches ([`crate::engine::base::cell::branch`]:
//!    the simulator's choice, elbow up, the least forearm roll) for a
//!    preset robot, within the cell's limits and 10° from the wrist
//!    singularity, then within the robot's limits without that margin;
//! 3. else the first solution found.

use std::ops::ControlFlow;

use nalgebra::Isometry3;

use super::config::{self, Config, Vendor};
use crate::engine::base::cell::branch;
use crate::engine::base::cell::workspace::cell_limits;
use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::ik::{Chain, DOF, within_limits};
use crate::engine::base::robot::{JointLimit, Robot, RobotChoice, presets};

/// Smallest `|q5|` (deg) of the preferred branch: the simulator's default
/// margin from the wrist singularity, so a target near a simulated pose
/// gets that pose's branch.
const PREFERRED_MIN_WRIST_DEG: f64 = 10.0;

/// Largest change of a joint (deg) from the nominal to the calibrated
/// solution. Kinematic errors of tenths of a degree and of millimetres
/// move the joints by about as much (Table 1's 1.9° joint-1 zero moves
/// joint 1 by 1.9°); a change beyond 10° means Newton left the branch,
/// near a singularity.
pub const MAX_BRANCH_CHANGE_DEG: f64 = 10.0;

/// Two solutions of one pose closer than this (deg, joint-space norm) are
/// the same branch: branches differ by tens of degrees.
const SAME_BRANCH_DEG: f64 = 1.0;

/// Two joint models of nominal parameters closer than this (deg, mm) are
/// the same preset.
const SAME_PRESET: f64 = 1e-6;

/// How the branch of a target was chosen.
#[derive(Debug, Clone, PartialEq)]
pub enum BranchRule {
    /// The target's written configuration.
    Configuration,
    /// The target's written configuration, which names another branch
    /// than the one nearest the calibration's poses (the nearest pose's
    /// id): followed, with a note.
    ConfigurationElsewhere(String),
    /// The nearest pose of the session (its id, the joint distance in deg).
    NearestPose(String, f64),
    /// The branch a cell teaches (the simulator's).
    Preferred,
    /// The first solution found.
    First,
    /// A joint target: its own joints.
    Joints,
}

impl BranchRule {
    /// For people.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Configuration => "its configuration".to_string(),
            Self::ConfigurationElsewhere(id) => format!(
                "its configuration, which names another branch than the calibration's pose {id} (the nearest): check that spherecal's reading of the controller's configuration fits the robot model"
            ),
            Self::NearestPose(id, d) => format!("the session's pose {id} ({d:.1}° away)"),
            Self::Preferred => "the branch a cell teaches (elbow up, least forearm roll)".into(),
            Self::First => "the first solution found".to_string(),
            Self::Joints => "its joints".to_string(),
        }
    }
}

/// The arm, nominal and calibrated.
#[derive(Debug, Clone)]
pub struct Arms {
    /// The controller's model.
    pub nominal: Robot,
    /// The calibrated model.
    pub calibrated: Robot,
    nominal_chain: Chain,
    calibrated_chain: Chain,
    /// Joint limits (deg): the preset's, or none for another robot.
    pub limits: Option<Vec<JointLimit>>,
    /// The preset the nominal model is, if any.
    pub preset: Option<RobotChoice>,
    /// The session's poses (id, joints deg) for the branch choice.
    poses: Vec<(String, [f64; DOF])>,
}

/// Wrapped joint-space distance (deg): the norm of the per-joint
/// differences, each moved by whole turns into (−180, 180].
#[must_use]
pub fn joint_distance(a: &[f64; DOF], b: &[f64; DOF]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| wrap_deg(x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

impl Arms {
    /// The arms of a 6-axis nominal and calibrated model; `poses` are the
    /// session's (for the branch choice), maybe none. `None` unless both
    /// models have 6 joints.
    #[must_use]
    pub fn new(
        nominal: Robot,
        calibrated: Robot,
        poses: Vec<(String, [f64; DOF])>,
    ) -> Option<Self> {
        let nominal_chain = Chain::new(&nominal)?;
        let calibrated_chain = Chain::new(&calibrated)?;
        let matched = presets().into_iter().find(|p| {
            p.robot.joints.len() == nominal.joints.len()
                && p.robot
                    .joints
                    .iter()
                    .zip(&nominal.joints)
                    .all(|(a, b)| (0..5).all(|k| (a.get(k) - b.get(k)).abs() < SAME_PRESET))
        });
        let preset_choice = matched.as_ref().and_then(|p| RobotChoice::from_key(p.key));
        let limits = matched.map(|p| p.limits);
        Some(Self {
            nominal,
            calibrated,
            nominal_chain,
            calibrated_chain,
            limits,
            preset: preset_choice,
            poses,
        })
    }

    fn limits_or_none(&self) -> Vec<JointLimit> {
        self.limits.clone().unwrap_or_else(|| {
            vec![
                JointLimit {
                    min: f64::NEG_INFINITY,
                    max: f64::INFINITY,
                };
                DOF
            ]
        })
    }

    /// Every solution (deg) of the nominal model for the flange pose
    /// `base_from_flange` (mm), distinct branches, readings in
    /// (−180, 180]. The limits are not applied: they bind the joints the
    /// robot is driven to, the calibrated solution.
    #[must_use]
    pub fn nominal_solutions(&self, base_from_flange: &Isometry3<f64>) -> Vec<[f64; DOF]> {
        let grid_limits = self.limits.clone().unwrap_or_default();
        let mut guesses = self
            .preset
            .map(|c| branch::arm_guesses(c, base_from_flange))
            .unwrap_or_default();
        guesses.extend(
            self.nominal_chain
                .arm_guess_grid(base_from_flange, &grid_limits),
        );
        let none = vec![
            JointLimit {
                min: f64::NEG_INFINITY,
                max: f64::INFINITY,
            };
            DOF
        ];
        self.nominal_chain
            .solutions(base_from_flange, &guesses, &none, 0.0)
    }

    /// The branch a cell teaches (rule 2 of the module doc), if the model
    /// is a preset and the pose has such a solution.
    fn preferred(&self, base_from_flange: &Isometry3<f64>) -> Option<[f64; DOF]> {
        let choice = self.preset?;
        let limits = self.limits.clone()?;
        let guesses = branch::arm_guesses(choice, base_from_flange);
        let wrist_offset = self.nominal_chain.theta(4);
        let dislike = |q: &[f64; DOF]| branch::wrist_dislike(choice, q, wrist_offset);
        let cell = cell_limits(choice.key(), &limits);
        [(cell, PREFERRED_MIN_WRIST_DEG), (limits, 0.0)]
            .iter()
            .find_map(|(lim, wrist)| {
                self.nominal_chain
                    .search(base_from_flange, &guesses, &dislike, |start| {
                        match self
                            .nominal_chain
                            .solve_from(base_from_flange, start, lim, *wrist)
                        {
                            Some(q) => ControlFlow::Break(q),
                            None => ControlFlow::Continue(()),
                        }
                    })
            })
    }

    /// The nominal solution a target means (module doc), with how it was
    /// chosen; `written` is its configuration as written, if any. `None`
    /// when the nominal model cannot reach the pose.
    #[must_use]
    pub fn nominal_branch(
        &self,
        base_from_flange: &Isometry3<f64>,
        written: Option<(Vendor, Config)>,
    ) -> Option<([f64; DOF], BranchRule)> {
        // Solutions within the limits (widened by what the calibrated
        // solution may move) first: another branch is for a pose none of
        // those reach.
        let all = self.nominal_solutions(base_from_flange);
        let widened: Vec<JointLimit> = self
            .limits_or_none()
            .iter()
            .map(|l| JointLimit {
                min: l.min - MAX_BRANCH_CHANGE_DEG,
                max: l.max + MAX_BRANCH_CHANGE_DEG,
            })
            .collect();
        let inside: Vec<[f64; DOF]> = all
            .iter()
            .copied()
            .filter(|q| within_limits(q, &widened))
            .collect();
        let solutions = if inside.is_empty() { all } else { inside };
        let nearest = solutions
            .iter()
            .filter_map(|q| {
                self.poses
                    .iter()
                    .map(|(id, p)| (id, joint_distance(q, p)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(id, d)| (*q, id.clone(), d))
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        if let Some((vendor, config)) = written {
            let limits = self.limits_or_none();
            let matching = solutions
                .iter()
                .flat_map(|q| turn_variants(q, &limits))
                .find(|q| vendor.config(q, config::posture(&self.nominal, q)) == config);
            if let Some(q) = matching {
                let rule = match &nearest {
                    Some((n, id, _)) if joint_distance(n, &q) > SAME_BRANCH_DEG => {
                        BranchRule::ConfigurationElsewhere(id.clone())
                    }
                    _ => BranchRule::Configuration,
                };
                return Some((q, rule));
            }
        }
        if let Some((q, id, d)) = nearest {
            return Some((q, BranchRule::NearestPose(id, d)));
        }
        if let Some(q) = self.preferred(base_from_flange) {
            return Some((q, BranchRule::Preferred));
        }
        solutions.first().map(|q| (*q, BranchRule::First))
    }

    /// The calibrated model's solution (deg) for the flange pose
    /// `base_from_flange` (mm), by Newton from the nominal solution
    /// `from`, readings not wrapped (they stay beside `from`'s).
    ///
    /// # Errors
    /// Newton does not converge, moves a joint by more than
    /// [`MAX_BRANCH_CHANGE_DEG`], or the solution breaks a joint limit.
    pub fn calibrated_solution(
        &self,
        base_from_flange: &Isometry3<f64>,
        from: &[f64; DOF],
    ) -> Result<[f64; DOF], Unsolved> {
        let q = self
            .calibrated_chain
            .inverse_kinematics(base_from_flange, from)
            .ok_or(Unsolved::NoConvergence)?;
        let change = q
            .iter()
            .zip(from)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if change > MAX_BRANCH_CHANGE_DEG {
            return Err(Unsolved::LeftBranch(change));
        }
        if let Some((joint, value, limit)) = self.broken_limit(&q) {
            return Err(Unsolved::Limit(joint, value, limit));
        }
        Ok(q)
    }

    /// The joint limit that `q` (deg) breaks, as `(joint 1-based, value,
    /// limit)`, if any.
    #[must_use]
    pub fn broken_limit(&self, q: &[f64; DOF]) -> Option<(usize, f64, f64)> {
        let limits = self.limits.as_ref()?;
        q.iter().zip(limits).enumerate().find_map(|(k, (v, l))| {
            if *v < l.min {
                Some((k + 1, *v, l.min))
            } else if *v > l.max {
                Some((k + 1, *v, l.max))
            } else {
                None
            }
        })
    }
}

/// Why the calibrated model has no solution on a branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unsolved {
    /// Newton did not converge (a pose at the edge of reach or singular).
    NoConvergence,
    /// Newton moved a joint this far (deg): it left the branch.
    LeftBranch(f64),
    /// Joint (1-based) at this value (deg) beyond this limit (deg).
    Limit(usize, f64, f64),
}

impl Unsolved {
    /// For people.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::NoConvergence => "the calibrated model has no solution on the nominal solution's branch (the pose is at the edge of reach or at a singularity)".to_string(),
            Self::LeftBranch(d) => format!(
                "the calibrated solution moves a joint by {d:.1}° from the nominal one (more than {MAX_BRANCH_CHANGE_DEG}°): the pose is at a singularity"
            ),
            Self::Limit(j, v, l) => format!(
                "the calibrated model needs joint {j} at {v:.3}°, beyond its limit {l}°"
            ),
        }
    }
}

/// `q` and its readings moved by whole turns on joints 1, 4 and 6 (the
/// joints whose turn a configuration names), within `limits`.
fn turn_variants(q: &[f64; DOF], limits: &[JointLimit]) -> Vec<[f64; DOF]> {
    let mut out = vec![*q];
    for k in [0, 3, 5] {
        let mut more = Vec::new();
        for v in &out {
            for turn in [-720.0, -360.0, 360.0, 720.0] {
                let mut w = *v;
                w[k] += turn;
                if limits
                    .get(k)
                    .is_some_and(|l| w[k] >= l.min && w[k] <= l.max)
                    && w[k].abs() <= 720.0
                {
                    more.push(w);
                }
            }
        }
        out.extend(more);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::base::robot::table1_errors;

    fn arms() -> Arms {
        let nominal = irb();
        let mut calibrated = nominal.clone();
        for (j, e) in calibrated.joints.iter_mut().zip(table1_errors()) {
            j.alpha += e.alpha;
            j.a += e.a;
            j.beta += e.beta;
            j.theta += e.theta;
            j.d += e.d;
        }
        Arms::new(nominal, calibrated, Vec::new()).unwrap()
    }

    fn irb() -> Robot {
        crate::engine::base::robot::irb2400().robot
    }

    #[test]
    fn the_calibrated_solution_stays_on_the_nominal_branch() {
        let arms = arms();
        assert_eq!(arms.preset, Some(RobotChoice::Irb2400));
        let q = [15.0, 25.0, 5.0, -40.0, 60.0, 30.0];
        let pose = arms.nominal.base_from_flange(&q);
        let (qn, rule) = arms.nominal_branch(&pose, None).unwrap();
        assert_eq!(rule, BranchRule::Preferred);
        assert!(joint_distance(&qn, &q) < 1e-6, "{qn:?}");
        let qc = arms.calibrated_solution(&pose, &qn).unwrap();
        let reached = arms.calibrated.base_from_flange(&qc);
        assert!((reached.translation.vector - pose.translation.vector).norm() < 1e-8);
        // Table 1 moves joint 1 by its 1.9° zero error, the rest by less.
        assert!((qc[0] - qn[0]).abs() > 1.5 && (qc[0] - qn[0]).abs() < 2.5);
    }

    #[test]
    fn a_written_configuration_picks_its_branch() {
        let arms = arms();
        let q = [15.0, 25.0, 5.0, -40.0, 60.0, 30.0];
        let pose = arms.nominal.base_from_flange(&q);
        let all = arms.nominal_solutions(&pose);
        let other = all
            .iter()
            .find(|s| joint_distance(s, &q) > 1.0)
            .copied()
            .unwrap();
        let cfg = Vendor::Abb.config(&other, config::posture(&arms.nominal, &other));
        let (qn, rule) = arms
            .nominal_branch(&pose, Some((Vendor::Abb, cfg)))
            .unwrap();
        assert_eq!(rule, BranchRule::Configuration);
        assert!(joint_distance(&qn, &other) < 1e-6);
        // A turn of joint 6 (limits ±400°) is named by cf6.
        let mut turned = q;
        turned[5] += 360.0;
        let cfg = Vendor::Abb.config(&turned, config::posture(&arms.nominal, &turned));
        let (qn, _) = arms
            .nominal_branch(&pose, Some((Vendor::Abb, cfg)))
            .unwrap();
        assert!((qn[5] - turned[5]).abs() < 1e-6, "{qn:?}");
    }

    #[test]
    fn unreachable_poses_have_no_branch() {
        let arms = arms();
        let far = Isometry3::translation(5000.0, 0.0, 0.0);
        assert!(arms.nominal_branch(&far, None).is_none());
    }
}
