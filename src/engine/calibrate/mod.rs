//! Layer 3, the paper's method, in the order it runs: the stripe's circle
//! and the sphere centre (eq. 21), the initial hand-eye (eq. 3-9), the
//! centre-distance error ε and the validation distances (eq. 20), and the
//! iterative identification of the hand-eye and kinematic errors
//! (eq. 10-19) with `ml`'s maximum-likelihood refinement beside it.
//!
//! | unit | holds | paper |
//! |---|---|---|
//! | [`stripe`] | segmentation of a profile, circle fit, the sphere centre | eq. 21 |
//! | [`handeye`] | the initial hand-eye: rotation by SVD, translation by least squares; the general solver for sets without pure translations | eq. 3-9 |
//! | [`validate`] | ε, statistics, Fig. 5 and 6 distances | eq. 20 |
//! | [`solve`] | prepare (each stripe fitted once), the one loop of Fig. 2 around a step: the paper's update or `ml`'s; held-out figure, progress, report | eq. 10-19 |

pub mod stripe;
pub mod handeye;
pub mod validate;
pub mod solve;
