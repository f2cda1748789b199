//! What a calibration records, as the result file stores it: the solver's
//! report ([`solver`]: the paper's loop or `ml`'s, [`ml`]: `ml`'s
//! records, [`loop_record`]: one pass of the loop). The solver fills them
//! (layer `calibrate`), the result format writes and reads them (layer
//! `files`), so they sit below both.

pub mod loop_record;
pub mod ml;
pub mod solver;

pub use loop_record::LoopRecord;
pub use ml::MlReport;
pub use solver::SolverReport;
