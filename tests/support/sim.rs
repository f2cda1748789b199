//! The simulated sessions the engine's tests start from, and the options
//! they solve them with.

use spherecal::engine::base::session::Session;
use spherecal::engine::calibrate::solve::{Method, Options};
use spherecal::engine::tools::simulate::{self, SimConfig, Truth};

/// A seeded simulated session and its truth.
pub fn simulate(config: &SimConfig) -> (Session, Truth) {
    simulate::simulate(config).expect("simulation")
}

/// Every noise source off (joints, stripes, centres, tracker).
pub fn noise_free(seed: u64) -> SimConfig {
    SimConfig {
        seed,
        joint_noise: 0.0,
        stripe_noise: 0.0,
        centre_noise: 0.0,
        tracker_noise: 0.0,
        ..SimConfig::default()
    }
}

/// The session's own options with `method`.
pub fn options(session: &Session, method: Method) -> Options {
    Options {
        method,
        ..Options::from_session(session)
    }
}

/// The paper's method, the baseline `ml` is compared with.
pub fn paper_options(session: &Session) -> Options {
    options(session, Method::Paper)
}
