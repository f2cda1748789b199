//! The branch a cell teaches: of the several joint solutions of a flange
//! pose, the one an operator would take. Per preset, the arm guesses the
//! inverse kinematics starts from (elbow up, joint 1 turned toward the
//! target) and the wrist it prefers. The simulator picks its poses with
//! these, and target compensation picks the branch of a target that
//! carries no configuration with them (so a target near a simulated pose
//! lands on that pose's branch).

use nalgebra::Isometry3;

use crate::engine::base::geometry::wrap_deg;
use crate::engine::base::robot::RobotChoice;
use crate::engine::base::robot::ik::DOF;

/// Arm guesses `(q1, q2, q3)` (deg) for a flange target (base frame, mm)
/// of preset `choice`: per-preset elbow-up configurations, joint 1 turned
/// toward the target.
#[must_use]
pub fn arm_guesses(choice: RobotChoice, target: &Isometry3<f64>) -> Vec<[f64; 3]> {
    let p = target.translation.vector;
    let heading = p.y.atan2(p.x).to_degrees();
    // The ABB arms point along +x at q1 = 0, the UR5e along −x.
    let (q1_offset, arms): (f64, &[[f64; 2]]) = match choice {
        RobotChoice::Irb2400 | RobotChoice::Irb120 => {
            (0.0, &[[20.0, 20.0], [40.0, 0.0], [0.0, 45.0], [50.0, 30.0]])
        }
        RobotChoice::Ur5e => (
            180.0,
            &[
                [-90.0, 90.0],
                [-50.0, 100.0],
                [-120.0, 110.0],
                [-60.0, 140.0],
            ],
        ),
    };
    let q1 = wrap_deg(heading + q1_offset);
    arms.iter().map(|a| [q1, a[0], a[1]]).collect()
}

/// How much a wrist solution `q` (deg) of preset `choice` is disliked
/// (lower first): the wrist a cell would teach. ABB wrists: the least
/// forearm roll `|q4|` (less cable wind-up); the UR5e: its tool-down
/// configuration, `q5 + wrist_offset < 0` (`wrist_offset`: the nominal
/// theta of joint 5, deg).
#[must_use]
pub fn wrist_dislike(choice: RobotChoice, q: &[f64; DOF], wrist_offset: f64) -> f64 {
    match choice {
        RobotChoice::Irb2400 | RobotChoice::Irb120 => wrap_deg(q[3]).abs(),
        RobotChoice::Ur5e => (q[4] + wrist_offset).signum(),
    }
}
