//! What a calibration records, as the result file stores it: the solver's
//! report ([`solver`]: the paper's loop or `ml`'s; [`ml`]: `ml`'s records,
//! its loss, the parameters it could not separate, the predicted errors
//! over the range and the volume; [`loop_record`]: one pass of the loop),
//! the validation block ([`validation`]) and the held-out figure
//! ([`held_out`]). The solver fills them (layer `calibrate`), the result
//! format writes and reads them (layer `files`), so they sit below both.

pub mod loop_record;
pub mod validation;
pub mod held_out;
pub mod ml;
pub mod solver;

pub use held_out::HeldOut;
pub use loop_record::LoopRecord;
pub use ml::MlReport;
pub use solver::SolverReport;
pub use validation::Validation;
