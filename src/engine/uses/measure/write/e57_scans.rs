//! E57 of a cloud: one scan a pose (see [`super`]).

use std::fs::File;
use std::io;

use e57::{
    E57Writer, Extension, Quaternion, Record, RecordDataType, RecordName, RecordValue, Transform,
    Translation,
};

use super::Provenance;
use crate::engine::uses::measure::cloud::Cloud;

/// E57 lengths are metres; the cloud's are mm.
const MM_PER_M: f64 = 1000.0;

/// The namespace of the σ attribute.
pub const NAMESPACE: &str = "spherecal";

/// The name of the σ attribute (mm, float).
pub const SIGMA_ATTRIBUTE: &str = "sigma_mm";

fn io_error(e: &e57::Error) -> io::Error {
    io::Error::other(format!("E57: {e}"))
}

/// A GUID-like id of the file and of its scans, from the provenance
/// (E57 wants one per object; they need only be unique in the file).
fn guid(provenance: &Provenance, what: &str) -> String {
    use sha2::Digest as _;
    let digest = sha2::Sha256::digest(format!("{}|{}", provenance.result, provenance.scan));
    let hex: String = digest.iter().take(8).map(|b| format!("{b:02x}")).collect();
    format!("{{spherecal-{hex}-{what}}}")
}

/// Writes the E57 of `cloud` to `file` (which must be readable and
/// seekable, as the E57 writer goes back to finish each section). Poses
/// without points are left out (an E57 scan needs points).
///
/// # Errors
/// The write fails.
pub fn write(file: &mut File, cloud: &Cloud, provenance: &Provenance) -> io::Result<()> {
    let mut writer = E57Writer::new(file, &guid(provenance, "file")).map_err(|e| io_error(&e))?;
    writer.set_coordinate_metadata(Some(format!(
        "{} (mm in spherecal; E57 metres); model {} of {}",
        cloud.frame, cloud.model, provenance.result
    )));
    let sigma = cloud.has_sigma();
    let mut prototype = vec![
        Record {
            name: RecordName::CartesianX,
            data_type: RecordDataType::Double {
                min: None,
                max: None,
            },
        },
        Record {
            name: RecordName::CartesianY,
            data_type: RecordDataType::Double {
                min: None,
                max: None,
            },
        },
        Record {
            name: RecordName::CartesianZ,
            data_type: RecordDataType::Double {
                min: None,
                max: None,
            },
        },
    ];
    if sigma {
        writer
            .register_extension(Extension::new(NAMESPACE, "urn:spherecal:measure"))
            .map_err(|e| io_error(&e))?;
        prototype.push(Record {
            name: RecordName::Unknown {
                namespace: NAMESPACE.into(),
                name: SIGMA_ATTRIBUTE.into(),
            },
            data_type: RecordDataType::Single {
                min: None,
                max: None,
            },
        });
    }
    for (k, pose) in cloud.poses.iter().enumerate() {
        if pose.points.is_empty() {
            continue;
        }
        let mut pc = writer
            .add_pointcloud(&guid(provenance, &k.to_string()), prototype.clone())
            .map_err(|e| io_error(&e))?;
        pc.set_name(Some(pose.id.clone()));
        pc.set_description(Some(format!(
            "pose {k} ({}): profile points in the sensor frame, the pose is the sensor's in the {}",
            pose.id, cloud.frame
        )));
        let t = pose.frame_from_sensor.translation.vector / MM_PER_M;
        let q = pose.frame_from_sensor.rotation.into_inner();
        // E57 wants w ≥ 0; q and −q are the same rotation.
        let q = if q.w < 0.0 { -q } else { q };
        pc.set_transform(Some(Transform {
            rotation: Quaternion {
                w: q.w,
                x: q.i,
                y: q.j,
                z: q.k,
            },
            translation: Translation {
                x: t.x,
                y: t.y,
                z: t.z,
            },
        }));
        for &p in &pose.points {
            let mut values = vec![
                RecordValue::Double(0.0),
                RecordValue::Double(p[0] / MM_PER_M),
                RecordValue::Double(p[1] / MM_PER_M),
            ];
            if sigma {
                // Narrowing intended: the attribute is a float.
                values.push(RecordValue::Single(pose.sigma_mm(p) as f32));
            }
            pc.add_point(values).map_err(|e| io_error(&e))?;
        }
        pc.finalize().map_err(|e| io_error(&e))?;
    }
    writer.finalize().map_err(|e| io_error(&e))
}
