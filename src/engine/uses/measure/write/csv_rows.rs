//! CSV of a cloud: `id,x,y,z,sigma_mm` (see [`super`]).

use std::io::{self, BufWriter, Write};

use crate::engine::uses::measure::cloud::Cloud;

/// The header row.
pub const HEADER: &str = "id,x,y,z,sigma_mm";

/// `id` as a CSV field: quoted (quotes doubled) when it holds a
/// separator, a quote, a line break or surrounding spaces.
fn field(id: &str) -> String {
    let plain =
        !id.contains([',', '"', '\n', '\r', ';', '\t']) && id.trim() == id && !id.starts_with('#');
    if plain {
        id.to_string()
    } else {
        format!("\"{}\"", id.replace('"', "\"\""))
    }
}

/// Writes the CSV of `cloud` to `out`: every number as Rust's `{}` of the
/// f64 (the shortest text that reads back to the same number).
///
/// # Errors
/// The write fails.
pub fn write(out: &mut impl Write, cloud: &Cloud) -> io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, out);
    writeln!(w, "{HEADER}")?;
    for pose in &cloud.poses {
        let id = field(&pose.id);
        for &p in &pose.points {
            let [x, y, z] = pose.position(p);
            writeln!(w, "{id},{x},{y},{z},{}", pose.sigma_mm(p))?;
        }
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_quoted_when_needed() {
        assert_eq!(field("c17"), "c17");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field(" lead"), "\" lead\"");
    }
}
