//! Binary little-endian PLY of a cloud (see [`super`]).

use std::io::{self, BufWriter, Write};

use super::{Provenance, one_line};
use crate::engine::uses::measure::cloud::Cloud;

/// Bytes of one vertex: three doubles, a float and a uint.
pub const VERTEX_BYTES: usize = 3 * 8 + 4 + 4;

/// The PLY header of `cloud`.
#[must_use]
pub fn header(cloud: &Cloud, provenance: &Provenance) -> String {
    use std::fmt::Write as _;
    let mut h = String::from("ply\nformat binary_little_endian 1.0\n");
    let _ = writeln!(
        h,
        "comment spherecal measure: result {}",
        one_line(&provenance.result)
    );
    let _ = writeln!(h, "comment scan {}", one_line(&provenance.scan));
    let _ = writeln!(
        h,
        "comment model {} (robot model and hand-eye of the result)",
        cloud.model
    );
    let _ = writeln!(h, "comment frame {}", one_line(&cloud.frame.to_string()));
    let _ = writeln!(
        h,
        "comment units mm; sigma_mm is the 1-sigma of the 3-D position (NaN: not computed); pose is the index of the pose below"
    );
    for (k, p) in cloud.poses.iter().enumerate() {
        let _ = writeln!(h, "comment pose {k} {}", one_line(&p.id));
    }
    let _ = writeln!(h, "element vertex {}", cloud.len());
    h.push_str(
        "property double x\nproperty double y\nproperty double z\nproperty float sigma_mm\nproperty uint pose\nend_header\n",
    );
    h
}

/// Writes the PLY of `cloud` to `out`.
///
/// # Errors
/// The write fails, or the cloud has more poses than a uint holds.
pub fn write(out: &mut impl Write, cloud: &Cloud, provenance: &Provenance) -> io::Result<()> {
    let mut w = BufWriter::with_capacity(1 << 20, out);
    w.write_all(header(cloud, provenance).as_bytes())?;
    let mut buf: Vec<u8> = Vec::new();
    for (k, pose) in cloud.poses.iter().enumerate() {
        let index = u32::try_from(k).map_err(|_| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                "more than 2^32 poses: PLY's uint pose index cannot hold them",
            )
        })?;
        buf.clear();
        buf.reserve(pose.points.len() * VERTEX_BYTES);
        for &p in &pose.points {
            let [x, y, z] = pose.position(p);
            buf.extend_from_slice(&x.to_le_bytes());
            buf.extend_from_slice(&y.to_le_bytes());
            buf.extend_from_slice(&z.to_le_bytes());
            // Narrowing intended: the format's sigma is a float.
            let sigma = pose.sigma_mm(p) as f32;
            buf.extend_from_slice(&sigma.to_le_bytes());
            buf.extend_from_slice(&index.to_le_bytes());
        }
        w.write_all(&buf)?;
    }
    w.flush()
}
