//! The user's own URDF, calibrated (issue 33, `export-model --format urdf
//! --robot X.urdf`): the file the session's robot was imported from,
//! written back with only the revolute joints' `<origin xyz rpy>` of the
//! chain changed ([`chain_origins`](crate::engine::base::robot::chain_origins):
//! the calibrated model's frames, each link keeping its offset from its
//! MDH frame, as robot_calibration composes corrections onto the joint
//! origins) and a `sensor` link with its fixed `sensor_joint` (the
//! calibrated hand-eye) added under the chain's tip link. Names, meshes,
//! inertials, limits, comments and every other byte are kept: the edits
//! are made in the text at the byte ranges the XML parser reports.

use std::path::Path;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::model::{urdf_number, urdf_origin};
use super::tool_data::{ROS_SENSOR_FRAME, sensor_urdf};
use crate::engine::base::robot::chain_origins::{ChainFitError, ChainStep, calibrated_origins};
use crate::engine::files::format::ResultFile;
use crate::engine::files::robot_import::RobotImportError;
use crate::engine::files::robot_import::urdf::{UrdfOptions, robot_from_urdf_with};

/// Millimetres per metre.
const MM_PER_M: f64 = 1000.0;

/// Why the URDF cannot be written back.
#[derive(Debug, thiserror::Error)]
pub enum UrdfBackError {
    /// The result has no robot (a pose-only result without one).
    #[error(
        "the result has no robot model (pose-only, no robot given): there are no joint origins to calibrate; export the tool data instead (--format tool)"
    )]
    NoRobot,
    /// The URDF does not import.
    #[error(transparent)]
    Import(#[from] RobotImportError),
    /// The URDF's chain is not the result's robot.
    #[error("{}: {source}", path.display())]
    Chain {
        /// The URDF.
        path: std::path::PathBuf,
        /// Why.
        source: ChainFitError,
    },
    /// The XML could not be edited (a joint or the root not where the
    /// parser put it, a `sensor` link already there).
    #[error("{}: {message}", path.display())]
    Edit {
        /// The URDF.
        path: std::path::PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// A calibrated URDF and what was done.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibratedUrdf {
    /// The file's new text.
    pub text: String,
    /// The joints whose origins changed, in chain order.
    pub joints: Vec<String>,
    /// The link the sensor was hung from.
    pub tip: String,
}

/// The URDF `text` (read from `path`) with the result's calibrated joint
/// origins and hand-eye (module doc). `tip` names the chain's tip link
/// when the file has several end links.
///
/// # Errors
/// [`UrdfBackError`]: no robot in the result, a URDF that does not import
/// or is not the result's nominal robot, a `sensor` link already there.
pub fn calibrated_urdf(
    result: &ResultFile,
    text: &str,
    path: &Path,
    tip: Option<&str>,
) -> Result<CalibratedUrdf, UrdfBackError> {
    let (Some(calibrated), Some(nominal)) = (result.robot.as_ref(), result.nominal()) else {
        return Err(UrdfBackError::NoRobot);
    };
    let options = UrdfOptions {
        tip: tip.map(str::to_owned),
        joints: None,
    };
    let imported = robot_from_urdf_with(text, path, &options)?;
    let edit = |message: String| UrdfBackError::Edit {
        path: path.to_path_buf(),
        message,
    };
    let doc = roxmltree::Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..roxmltree::ParsingOptions::default()
        },
    )
    .map_err(|e| edit(e.to_string()))?;
    let root = doc.root_element();
    let joints: Vec<roxmltree::Node<'_, '_>> = root
        .children()
        .filter(|n| n.has_tag_name("joint"))
        .collect();
    if root
        .children()
        .any(|n| n.has_tag_name("link") && n.attribute("name") == Some(ROS_SENSOR_FRAME))
    {
        return Err(edit(format!(
            "the file already has a link named `{ROS_SENSOR_FRAME}`"
        )));
    }
    // The chain, root to tip, as the parser sees it.
    let mut chain = Vec::new();
    let mut link = imported.tip_link.clone();
    while link != imported.root_link {
        let joint = joints
            .iter()
            .find(|j| child_link(j) == Some(link.as_str()))
            .ok_or_else(|| edit(format!("no joint has `{link}` as its child")))?;
        chain.push(*joint);
        link = joint
            .children()
            .find(|n| n.has_tag_name("parent"))
            .and_then(|n| n.attribute("link"))
            .ok_or_else(|| edit(format!("joint above `{link}` has no parent")))?
            .to_owned();
        if chain.len() > joints.len() {
            return Err(edit("the joints form a loop".to_string()));
        }
    }
    chain.reverse();
    let steps: Vec<ChainStep> = chain.iter().map(step_of).collect();
    let origins = calibrated_origins(&steps, &nominal, calibrated).map_err(|source| {
        UrdfBackError::Chain {
            path: path.to_path_buf(),
            source,
        }
    })?;
    let mut edits: Vec<(std::ops::Range<usize>, String)> = Vec::new();
    let mut changed = Vec::new();
    for ((node, step), origin) in chain.iter().zip(&steps).zip(&origins) {
        if step.axis.is_none() {
            continue;
        }
        changed.push(step.name.clone());
        let ([x, y, z], [roll, pitch, yaw]) = urdf_origin(origin);
        let xyz = [x, y, z].map(urdf_number).join(" ");
        let rpy = [roll, pitch, yaw].map(urdf_number).join(" ");
        if let Some(o) = node.children().find(|n| n.has_tag_name("origin")) {
            for (name, value) in [("xyz", xyz), ("rpy", rpy)] {
                if let Some(a) = o.attribute_node(name) {
                    edits.push((a.range_value(), value));
                } else {
                    let at = o.range().start + "<origin".len();
                    edits.push((at..at, format!(" {name}=\"{value}\"")));
                }
            }
        } else {
            let at = start_tag_end(text, node)
                .ok_or_else(|| edit(format!("joint {} has no closing `>`", step.name)))?;
            edits.push((at..at, format!("<origin xyz=\"{xyz}\" rpy=\"{rpy}\"/>")));
        }
    }
    // The sensor, just before `</robot>`.
    let end = root.range().end;
    let close = text[..end]
        .rfind("</")
        .filter(|&i| i > root.range().start)
        .ok_or_else(|| edit("the <robot> element has no closing tag".to_string()))?;
    let line_start = text[..close].rfind('\n').map_or(0, |i| i + 1);
    let at = if text[line_start..close].trim().is_empty() {
        line_start
    } else {
        close
    };
    let mut sensor =
        String::from("  <!-- Added by spherecal: the calibrated sensor (hand-eye). -->\n");
    sensor.push_str(&sensor_urdf(&result.hand_eye, &imported.tip_link, "  "));
    edits.push((at..at, sensor));
    edits.sort_by_key(|(r, _)| std::cmp::Reverse(r.start));
    let mut out = text.to_owned();
    for (range, new) in edits {
        out.replace_range(range, &new);
    }
    Ok(CalibratedUrdf {
        text: out,
        joints: changed,
        tip: imported.tip_link,
    })
}

/// The `link` of a joint's `<child>`.
fn child_link<'a>(joint: &roxmltree::Node<'a, '_>) -> Option<&'a str> {
    joint
        .children()
        .find(|n| n.has_tag_name("child"))
        .and_then(|n| n.attribute("link"))
}

/// Where the start tag of `node` ends (just after its `>`).
fn start_tag_end(text: &str, node: &roxmltree::Node<'_, '_>) -> Option<usize> {
    let from = node
        .attributes()
        .map(|a| a.range().end)
        .max()
        .unwrap_or(node.range().start);
    text[from..].find('>').map(|i| from + i + 1)
}

/// A chain step of a joint element (origin in mm; a revolute or
/// continuous joint's axis, default x as URDF has it).
fn step_of(node: &roxmltree::Node<'_, '_>) -> ChainStep {
    let numbers = |el: &str, attr: &str| -> [f64; 3] {
        let mut v = [0.0; 3];
        if let Some(text) = node
            .children()
            .find(|n| n.has_tag_name(el))
            .and_then(|n| n.attribute(attr))
        {
            for (k, x) in text.split_whitespace().take(3).enumerate() {
                v[k] = x.parse().unwrap_or(0.0);
            }
        }
        v
    };
    let [x, y, z] = numbers("origin", "xyz");
    let [roll, pitch, yaw] = numbers("origin", "rpy");
    let origin = Isometry3::from_parts(
        Translation3::new(x * MM_PER_M, y * MM_PER_M, z * MM_PER_M),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    );
    let moving = matches!(node.attribute("type"), Some("revolute" | "continuous"));
    let axis = moving.then(|| {
        let has_axis = node.children().any(|n| n.has_tag_name("axis"));
        let a = if has_axis {
            Vector3::from(numbers("axis", "xyz"))
        } else {
            Vector3::x()
        };
        a.try_normalize(0.0).unwrap_or_else(Vector3::x)
    });
    ChainStep {
        name: node.attribute("name").unwrap_or_default().to_owned(),
        origin,
        axis,
    }
}
