//! CSV of a cloud: `id,x,y,z,sigma_mm` (see [`super`]).

use std::io::{self, BufWriter, Write};

use crate::engine::files::table::csv_field;
use crate::engine::uses::measure::cloud::Cloud;

/// The header row.
pub const HEADER: &str = "id,x,y,z,sigma_mm";

/// Writes the CSV of `cloud` to `out`: every number as Rust's `{}` of the
/// f64 (the shortest text that reads back to the same number).
///
/// # Errors
/// The write fails.
pub fn write(out: &mut impl Write, cloud: &Cloud) -> io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, out);
    writeln!(w, "{HEADER}")?;
    for pose in &cloud.poses {
        let id = csv_field(&pose.id);
        for &p in &pose.points {
            let [x, y, z] = pose.position(p);
            writeln!(w, "{id},{x},{y},{z},{}", pose.sigma_mm(p))?;
        }
    }
    w.flush()
}
