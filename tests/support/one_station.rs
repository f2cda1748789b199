//! A real set's shape, simulated: one sphere station seen from a few
//! flange poses the controller reports with its absolute error, every
//! pose `identify` (shared by `tests/engine/held_out.rs` and the UI test).
#![allow(dead_code, clippy::unwrap_used)]

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use spherecal::engine::base::session::{Session, Use};
use spherecal::engine::calibrate::solve::paper::Pairing;
use spherecal::engine::calibrate::solve::{self, Method, Options};
use spherecal::engine::tools::simulate::{self, SimConfig};

/// A pose-only session of one sphere station seen from `poses` flange
/// poses, each reported with an error of σ `pose_sigma` mm per
/// coordinate (a real robot's absolute accuracy), as real sets come: every
/// pose `identify`, the initial hand-eye in the file.
pub fn one_station(seed: u64, poses: usize, pose_sigma: f64) -> Session {
    let config = SimConfig {
        seed,
        n_identify: 1,
        n_validate: 0,
        poses_per_station: poses,
        ..SimConfig::default()
    };
    let (mut session, truth) = simulate::simulate(&config).unwrap();
    let robot = truth.true_robot();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, pose_sigma).unwrap();
    for m in &mut session.measurements {
        let mut pose = robot.base_from_flange(&m.joints);
        for k in 0..3 {
            pose.translation.vector[k] += noise.sample(&mut rng);
        }
        m.flange = Some(pose);
        m.joints.clear();
    }
    session.robot_given = false;
    session.robot = spherecal::engine::base::robot::Robot::new(String::new(), Vec::new());
    session.base_given = false;
    session.flange_given = false;
    session.hand_eye = Some(solve::prepare(&session).unwrap().hand_eye_initial);
    session
        .measurements
        .retain(|m| matches!(m.usage, Use::Identify));
    session.reference_distances.clear();
    session
}

/// `session` started at the hand-eye with the least scatter over every
/// pair (the paper's method with all pairs, run to its end): the best ε
/// the data allow, which the paper's disjoint pairs can only leave.
pub fn best_scatter_start(mut session: Session) -> Session {
    let mut all = Options {
        method: Method::Paper,
        ..Options::from_session(&session)
    };
    all.paper.pairing = Pairing::All;
    all.threshold = 0.0;
    all.held_out = false;
    let (_, best) = solve::calibrate(&session, &all).unwrap();
    session.hand_eye = Some(best.hand_eye);
    session
}
