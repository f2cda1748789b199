//! Robot import from a URDF file: the serial chain of revolute joints from
//! the root link to a tip link, converted to the modified-DH model of
//! [`kinematics`](super::kinematics) (lengths in mm, angles in deg).
//!
//! # What is read
//!
//! The file is parsed with `urdf-rs`. The chain runs from the tree's root
//! link to a tip link: the one the caller names ([`UrdfOptions::tip`], e.g.
//! `tool0` or `flange`), or by default the only end link of the tree that
//! is reached through moving joints (ROS-Industrial files also hang fixed
//! frames such as `base` off the root; those are ignored). `revolute` and
//! `continuous` joints move; `fixed` joints are folded into their
//! neighbours; any other type (`prismatic`, `floating`, `planar`,
//! `spherical`), a `mimic` joint, a zero axis, a branch without a chosen
//! tip or a joint count other than [`UrdfOptions::joints`] is an error
//! naming the file and the joint or link. URDF metres become mm, radians
//! become degrees; joint limits come from `<limit lower upper>` (a
//! `continuous` joint, or an omitted bound in a URDF 1.2 file, gives an
//! infinite limit).
//!
//! # The conversion
//!
//! At `q = 0` every moving joint `i` is a line in the root frame: point
//! `p_i` (the joint frame's origin) and direction `z_i` (the joint's
//! `<axis>` in the root frame, sign kept, so a positive URDF reading turns
//! the same way as a positive model reading). The MDH frames are built on
//! these lines:
//!
//! - frame `i` has its z along axis `i` and its origin on it;
//! - for non-parallel axes `i`, `i+1`, `x_i` runs along their common normal
//!   from axis `i` to axis `i+1` (so `a_{i+1} ≥ 0`) and frame `i` sits at
//!   the normal's foot on axis `i`; when the axes intersect,
//!   `x_i = ±(z_i × z_{i+1})`, the sign nearest the previous `x` (so the
//!   zero offset `theta` is small);
//! - for parallel axes the normal is not unique: frame `i` sits where
//!   `x_{i-1}` meets axis `i` (so `d_i = 0`) and `x_i` is the perpendicular
//!   from there to axis `i+1`. For *nearly* parallel axes (sine of the
//!   angle below 0.01) the same construction is used with the plane through
//!   frame `i` normal to `z_i`, and Hayati's `beta` of joint `i+1` takes up
//!   the small tilt, so the model stays exact without a far-away common
//!   normal. A nominal URDF has exactly parallel axes (they share the same
//!   composed rotation), so its `beta` are all 0 (tilts at rounding level,
//!   below 1e-14 rad, are dropped);
//! - frame 0 has the axes of frame 1 at `q = 0` (joint 1 has `alpha = a =
//!   beta = theta = 0`) and its origin at the foot of the perpendicular
//!   from the root link's origin onto axis 1, so joint 1 keeps the column
//!   height as `d_1` and the base transform `B` (root link → frame 0) is
//!   the identity for the usual files whose axis 1 is the root's z axis;
//! - the last frame sits on axis `n` at the foot of the perpendicular from
//!   the tip link's origin, its x along the tip's x (or its y, when the tip
//!   x is within 30° of the axis) projected normal to the axis; the flange
//!   transform `F` (frame `n` → tip link) is then a pure translation normal
//!   to the axis when the tip's z is along the axis, and the identity for a
//!   `tool0` at the flange centre.
//!
//! `theta_i` is whatever offset puts frame `i` where the URDF has it at
//! `q = 0`, so URDF reading = model reading for every joint; forward
//! kinematics of the two then agree for all `q` (both are products of
//! rotations about the same axis lines applied to the same zero pose).
//!
//! # Limits
//!
//! A URDF is untrusted text. Before `urdf-rs` sees it, one linear pass
//! ([`check_xml_shape`]) refuses elements nested deeper than
//! [`MAX_URDF_DEPTH`] (`urdf-rs`' XML reader recurses once a level and
//! slows with the square of the depth: 20,000 levels overflowed the stack,
//! 500,000 unclosed tags ran for minutes); a file beyond [`MAX_URDF_BYTES`]
//! is refused unread. Two links or two joints of one name, an origin or
//! axis that is not finite or beyond the session's plausibility limits
//! (100 m, 36,000°) are errors naming the joint, and so is a converted
//! MDH parameter beyond those limits.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::error::RobotImportError;
use crate::engine::base::limits;
use crate::engine::base::numeric::show;
use crate::engine::base::robot::kinematics::{Joint, JointLimit, Robot};
use crate::engine::files::table::excerpt;

/// Sine of the angle between consecutive axes below which they are treated
/// as (nearly) parallel: frame placed with the perpendicular plane, the
/// tilt in `beta`.
const PARALLEL_SIN: f64 = 0.01;

/// Common-normal length (mm) below which two axes are taken to intersect.
const INTERSECT_MM: f64 = 1e-9;

/// A `beta` (rad) below this is rounding noise of exactly parallel or
/// normal axes and set to 0 (it moves a point a metre away by 1e-11 mm).
const BETA_NOISE: f64 = 1e-14;

/// Deepest element nesting accepted in a URDF. A robot description is
/// shallow: `robot > link > visual > geometry > mesh` is 5 levels, Gazebo
/// and `ros2_control` blocks add a few; 64 leaves room for any real file
/// while keeping `urdf-rs`' recursive reader far from the stack's end and
/// its time (quadratic in the depth) negligible.
pub const MAX_URDF_DEPTH: usize = 64;

/// Largest URDF file read, bytes (64 MiB): meshes live in their own files,
/// and even a xacro-expanded cell of several robots is a few MB.
pub const MAX_URDF_BYTES: u64 = 64 << 20;

/// Longest message of `urdf-rs` passed on, characters (its messages may
/// quote the offending text).
const MAX_PARSER_MESSAGE_CHARS: usize = 400;

/// Which chain to take from a URDF.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct UrdfOptions {
    /// Name of the tip link (e.g. `tool0`, `flange`). `None`: the only end
    /// link reached through moving joints; several such links are an error.
    pub tip: Option<String>,
    /// Number of moving joints the chain must have (e.g. 6). `None`: any
    /// number from 1 up.
    pub joints: Option<usize>,
}

impl UrdfOptions {
    /// Options naming the tip link.
    #[must_use]
    pub fn with_tip(tip: impl Into<String>) -> Self {
        Self {
            tip: Some(tip.into()),
            joints: None,
        }
    }
}

/// A robot read from a URDF: the model plus what the URDF says about its
/// joints.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfRobot {
    /// The model: MDH joints, `base` = root link → frame 0, `flange` =
    /// frame `n` → tip link, mm and deg.
    pub robot: Robot,
    /// Joint limits from `<limit>`, deg, one per joint (infinite for
    /// `continuous` joints and omitted URDF 1.2 bounds).
    pub limits: Vec<JointLimit>,
    /// The URDF names of the moving joints, base to tip.
    pub joint_names: Vec<String>,
    /// The root link (the frame `base_from_flange` is expressed in).
    pub root_link: String,
    /// The tip link (the frame `base_from_flange` ends in).
    pub tip_link: String,
}

/// The error of a URDF beyond [`MAX_URDF_BYTES`].
fn too_large(path: &Path, size: u64) -> RobotImportError {
    RobotImportError::UrdfSyntax {
        path: path.to_path_buf(),
        message: format!(
            "the file has {size} bytes, more than the {} MiB a robot description may have",
            MAX_URDF_BYTES >> 20
        ),
    }
}

/// Checks the element structure of an XML text in one linear pass,
/// before a parser that recurses sees it: elements nested at most
/// [`MAX_URDF_DEPTH`] deep. Comments, CDATA, processing instructions,
/// declarations and quoted attribute values are skipped as XML defines
/// them; anything else malformed is left to the parser. Returns the
/// message and the 1-based line of the first element too deep.
///
/// # Errors
/// `(line, message)` of the first element beyond the depth limit.
pub fn check_xml_shape(text: &str) -> Result<(), (usize, String)> {
    let b = text.as_bytes();
    let (mut i, mut line, mut depth) = (0usize, 1usize, 0usize);
    // Advances `i` past the first `end` from `from`, counting lines; to
    // the end of the text when there is none.
    let skip_to = |from: usize, end: &[u8], line: &mut usize| -> usize {
        let mut j = from;
        while j < b.len() {
            if b[j..].starts_with(end) {
                return j + end.len();
            }
            if b[j] == b'\n' {
                *line += 1;
            }
            j += 1;
        }
        b.len()
    };
    while i < b.len() {
        match b[i] {
            b'\n' => {
                line += 1;
                i += 1;
            }
            b'<' => {
                let rest = &b[i..];
                if rest.starts_with(b"<!--") {
                    i = skip_to(i + 4, b"-->", &mut line);
                } else if rest.starts_with(b"<![CDATA[") {
                    i = skip_to(i + 9, b"]]>", &mut line);
                } else if rest.starts_with(b"<?") {
                    i = skip_to(i + 2, b"?>", &mut line);
                } else if rest.starts_with(b"<!") {
                    // A declaration; its internal subset `[...]` may hold `>`.
                    let mut j = i + 2;
                    let mut bracket = 0usize;
                    while j < b.len() {
                        match b[j] {
                            b'[' => bracket += 1,
                            b']' => bracket = bracket.saturating_sub(1),
                            b'>' if bracket == 0 => break,
                            b'\n' => line += 1,
                            _ => {}
                        }
                        j += 1;
                    }
                    i = j + 1;
                } else if rest.starts_with(b"</") {
                    depth = depth.saturating_sub(1);
                    i = skip_to(i + 2, b">", &mut line);
                } else {
                    // A start tag: to its `>`, outside quoted values.
                    let start_line = line;
                    let mut j = i + 1;
                    let mut quote: Option<u8> = None;
                    while j < b.len() {
                        let c = b[j];
                        if c == b'\n' {
                            line += 1;
                        }
                        match quote {
                            Some(q) if c == q => quote = None,
                            Some(_) => {}
                            None if c == b'"' || c == b'\'' => quote = Some(c),
                            None if c == b'>' => break,
                            None => {}
                        }
                        j += 1;
                    }
                    let empty = j > i + 1 && j < b.len() && b[j - 1] == b'/';
                    if !empty {
                        depth += 1;
                        if depth > MAX_URDF_DEPTH {
                            return Err((
                                start_line,
                                format!(
                                    "elements nested more than {MAX_URDF_DEPTH} levels deep (line {start_line}): not a robot description"
                                ),
                            ));
                        }
                    }
                    i = j + 1;
                }
            }
            _ => i += 1,
        }
    }
    Ok(())
}

/// The robot of a URDF text with the default chain: from the root link to
/// the only end link reached through moving joints. `source` names the
/// file in errors.
///
/// # Errors
/// As [`robot_from_urdf_with`].
pub fn robot_from_urdf(text: &str, source: &Path) -> Result<UrdfRobot, RobotImportError> {
    robot_from_urdf_with(text, source, &UrdfOptions::default())
}

/// The robot of a URDF text, chain chosen by `options` (module docs).
/// `source` names the file in errors.
///
/// # Errors
/// [`RobotImportError::UrdfSyntax`] for a text `urdf-rs` rejects,
/// [`RobotImportError::UrdfTree`] when the links do not give one chain to
/// the tip, [`RobotImportError::UrdfJoint`] for a joint the model cannot
/// hold, [`RobotImportError::JointCount`] when `options.joints` is not met.
pub fn robot_from_urdf_with(
    text: &str,
    source: &Path,
    options: &UrdfOptions,
) -> Result<UrdfRobot, RobotImportError> {
    if text.len() as u64 > MAX_URDF_BYTES {
        return Err(too_large(source, text.len() as u64));
    }
    check_xml_shape(text).map_err(|(_, message)| RobotImportError::UrdfSyntax {
        path: source.to_path_buf(),
        message,
    })?;
    let urdf = urdf_rs::read_from_string(text).map_err(|e| RobotImportError::UrdfSyntax {
        path: source.to_path_buf(),
        message: crate::engine::files::table::clip(&e.to_string(), MAX_PARSER_MESSAGE_CHARS),
    })?;
    let tree = Tree::new(&urdf, source)?;
    let tip = match &options.tip {
        Some(name) => tree.named_link(name)?,
        None => tree.default_tip()?,
    };
    let chain = tree.chain_to(tip)?;
    let root = chain
        .first()
        .map_or(tip, |j| j.parent.link.as_str())
        .to_owned();
    let geometry = chain_geometry(&chain, source)?;
    check_count(&geometry, options.joints, source, &root, tip)?;
    let mdh = mdh_from_axes(&geometry.axes, &geometry.tip);
    check_model(&mdh, &geometry.names, source)?;
    let name = if urdf.name.is_empty() {
        file_stem(source)
    } else {
        urdf.name.clone()
    };
    Ok(UrdfRobot {
        robot: Robot {
            name,
            joints: mdh.joints,
            base: mdh.base,
            flange: mdh.flange,
        },
        limits: geometry.limits,
        joint_names: geometry.names,
        root_link: root,
        tip_link: tip.to_owned(),
    })
}

/// The file name without extension, for a robot without a name.
fn file_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "robot".to_owned(), |s| s.to_string_lossy().into_owned())
}

/// The chain's moving-joint count against the caller's expectation.
fn check_count(
    geometry: &ChainGeometry,
    expected: Option<usize>,
    path: &Path,
    root: &str,
    tip: &str,
) -> Result<(), RobotImportError> {
    let found = geometry.axes.len();
    let ok = expected.map_or(found >= 1, |e| e == found);
    if ok {
        return Ok(());
    }
    Err(RobotImportError::JointCount {
        path: path.to_path_buf(),
        root: root.to_owned(),
        tip: tip.to_owned(),
        joints: geometry.names.clone(),
        found,
        expected,
    })
}

/// The link tree of a URDF: each link's parent joint and child joints.
struct Tree<'a> {
    /// The file, for errors.
    path: &'a Path,
    /// Link names in file order.
    links: Vec<&'a str>,
    /// The same names, for lookups in constant time.
    link_set: HashSet<&'a str>,
    /// Child link → the joint above it.
    parent: HashMap<&'a str, &'a urdf_rs::Joint>,
    /// Parent link → number of joints below it.
    n_children: HashMap<&'a str, usize>,
}

impl<'a> Tree<'a> {
    /// The tree of `urdf`; every joint must join declared links and every
    /// link have at most one parent joint.
    fn new(urdf: &'a urdf_rs::Robot, path: &'a Path) -> Result<Self, RobotImportError> {
        let mut tree = Self {
            path,
            links: urdf.links.iter().map(|l| l.name.as_str()).collect(),
            link_set: HashSet::with_capacity(urdf.links.len()),
            parent: HashMap::new(),
            n_children: HashMap::new(),
        };
        for link in &tree.links {
            if !tree.link_set.insert(link) {
                return Err(tree.error(format!(
                    "two links are named `{}`: every link needs its own name",
                    excerpt(link)
                )));
            }
        }
        let mut joint_names: HashSet<&str> = HashSet::with_capacity(urdf.joints.len());
        for joint in &urdf.joints {
            if !joint_names.insert(&joint.name) {
                return Err(joint_error(
                    path,
                    joint,
                    "two joints have this name: every joint needs its own name".to_owned(),
                ));
            }
            for link in [&joint.parent.link, &joint.child.link] {
                if !tree.link_set.contains(link.as_str()) {
                    return Err(joint_error(
                        path,
                        joint,
                        format!("link `{}` is not declared", excerpt(link)),
                    ));
                }
            }
            if let Some(other) = tree.parent.insert(&joint.child.link, joint) {
                return Err(tree.error(format!(
                    "link `{}` is the child of two joints, `{}` and `{}`",
                    joint.child.link, other.name, joint.name
                )));
            }
            *tree.n_children.entry(&joint.parent.link).or_default() += 1;
        }
        Ok(tree)
    }

    /// A tree error for this file.
    fn error(&self, message: String) -> RobotImportError {
        RobotImportError::UrdfTree {
            path: self.path.to_path_buf(),
            message,
        }
    }

    /// The link called `name`, or an error listing the links.
    fn named_link(&self, name: &str) -> Result<&'a str, RobotImportError> {
        self.link_set.get(name).copied().ok_or_else(|| {
            self.error(excerpt(&format!(
                "no link named `{name}` (links: {})",
                self.links.join(", ")
            )))
        })
    }

    /// The only end link reached through at least one moving joint. Each
    /// link's answer is remembered, so the walk is linear in the links.
    fn default_tip(&self) -> Result<&'a str, RobotImportError> {
        let mut moving_above: HashMap<&'a str, bool> = HashMap::new();
        let mut ends = Vec::new();
        for link in &self.links {
            if self.n_children.contains_key(link) {
                continue;
            }
            if self.moving_above(link, &mut moving_above)? {
                ends.push(*link);
            }
        }
        match ends.as_slice() {
            [tip] => Ok(tip),
            [] => Err(self.error("no moving joint: the tree has no revolute chain".into())),
            _ => Err(self.error(format!(
                "the tree branches: end links {} are all reached through moving joints; \
                 name the tip link (e.g. tool0 or flange)",
                ends.iter()
                    .map(|l| format!("`{l}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }

    /// Whether a moving joint lies between the root and `link`, with the
    /// answers known so far in `memo` (and the new ones added).
    fn moving_above(
        &self,
        link: &'a str,
        memo: &mut HashMap<&'a str, bool>,
    ) -> Result<bool, RobotImportError> {
        let mut walked: Vec<&'a str> = Vec::new();
        let mut at = link;
        let answer = loop {
            if let Some(&known) = memo.get(at) {
                break known;
            }
            let Some(joint) = self.parent.get(at) else {
                break false;
            };
            if walked.len() > self.parent.len() {
                return Err(self.error(format!(
                    "the joints above link `{}` form a loop",
                    excerpt(link)
                )));
            }
            walked.push(at);
            if is_moving(joint) {
                break true;
            }
            at = &joint.parent.link;
        };
        // Every link walked has the answer of the first one known above it
        // (a moving joint above a link is above each link below it).
        for w in walked {
            memo.insert(w, answer);
        }
        Ok(answer)
    }

    /// The joints from the root down to `tip`, root first.
    fn chain_to(&self, tip: &str) -> Result<Vec<&'a urdf_rs::Joint>, RobotImportError> {
        let mut chain = Vec::new();
        let mut link = tip;
        while let Some(joint) = self.parent.get(link) {
            if chain.len() > self.parent.len() {
                return Err(self.error(format!("the joints above link `{tip}` form a loop")));
            }
            chain.push(*joint);
            link = &joint.parent.link;
        }
        chain.reverse();
        Ok(chain)
    }
}

/// Whether a joint moves (anything but `fixed`; unsupported moving types
/// are rejected by [`chain_geometry`]).
fn is_moving(joint: &urdf_rs::Joint) -> bool {
    joint.joint_type != urdf_rs::JointType::Fixed
}

/// An error about one joint.
fn joint_error(path: &Path, joint: &urdf_rs::Joint, message: String) -> RobotImportError {
    RobotImportError::UrdfJoint {
        path: path.to_path_buf(),
        joint: joint.name.clone(),
        message,
    }
}

/// A joint axis at `q = 0` in the root frame: a point (mm) and a unit
/// direction.
#[derive(Debug, Clone, Copy)]
struct AxisLine {
    /// A point on the axis (the joint frame's origin), mm.
    point: Vector3<f64>,
    /// Unit direction; positive readings turn right-handed about it.
    dir: Vector3<f64>,
}

/// The chain at `q = 0`: the moving joints' axes, names and limits, and
/// the tip link's pose, all in the root frame (mm).
struct ChainGeometry {
    /// Axis lines, base to tip.
    axes: Vec<AxisLine>,
    /// URDF joint names, base to tip.
    names: Vec<String>,
    /// Limits, deg.
    limits: Vec<JointLimit>,
    /// Root → tip link at `q = 0`.
    tip: Isometry3<f64>,
}

/// Walks the chain at `q = 0`, composing the joint origins (fixed joints
/// folded in) and recording each moving joint's axis line.
fn chain_geometry(
    chain: &[&urdf_rs::Joint],
    path: &Path,
) -> Result<ChainGeometry, RobotImportError> {
    let mut pose = Isometry3::identity();
    let mut geometry = ChainGeometry {
        axes: Vec::new(),
        names: Vec::new(),
        limits: Vec::new(),
        tip: Isometry3::identity(),
    };
    for joint in chain {
        check_origin(joint, path)?;
        pose *= origin_mm(&joint.origin);
        if !revolute_kind(joint, path)? {
            continue;
        }
        let axis = unit_axis(joint, path)?;
        geometry.axes.push(AxisLine {
            point: pose.translation.vector,
            dir: pose.rotation * axis,
        });
        geometry.names.push(joint.name.clone());
        geometry.limits.push(joint_limit(joint, path)?);
    }
    geometry.tip = pose;
    Ok(geometry)
}

/// Refuses a joint `<origin>` or `<axis>` with a number that is not
/// finite or not plausible (translation beyond the session's length
/// limit, an angle beyond its angle limit): it would not fail later, it
/// would quietly become a different robot.
fn check_origin(joint: &urdf_rs::Joint, path: &Path) -> Result<(), RobotImportError> {
    let [x, y, z] = joint.origin.xyz.0;
    let [r, p, w] = joint.origin.rpy.0;
    let length = limits::LENGTH_MM / 1000.0;
    let angle = limits::ANGLE_DEG.to_radians();
    let fail = |what: &str, values: [f64; 3], limit: String| {
        Err(joint_error(
            path,
            joint,
            format!(
                "{what}=\"{} {} {}\" is not plausible: every value must be finite and at most {limit}",
                show(values[0]),
                show(values[1]),
                show(values[2])
            ),
        ))
    };
    if ![x, y, z].iter().all(|v| v.is_finite() && v.abs() <= length) {
        return fail("origin xyz", [x, y, z], format!("{length} m"));
    }
    if ![r, p, w].iter().all(|v| v.is_finite() && v.abs() <= angle) {
        return fail("origin rpy", [r, p, w], format!("{} rad", show(angle)));
    }
    let axis = joint.axis.xyz.0;
    if !axis.iter().all(|v| v.is_finite()) {
        return fail("axis xyz", axis, "finite".to_owned());
    }
    Ok(())
}

/// Refuses a converted model with a parameter or transform beyond the
/// session's plausibility limits (a chain that is nearly degenerate can
/// put a common normal far away), naming the joint.
fn check_model(mdh: &MdhChain, names: &[String], path: &Path) -> Result<(), RobotImportError> {
    for (joint, name) in mdh.joints.iter().zip(names) {
        for (key, v, limit, unit) in [
            ("alpha", joint.alpha, limits::ANGLE_DEG, "deg"),
            ("a", joint.a, limits::LENGTH_MM, "mm"),
            ("beta", joint.beta, limits::ANGLE_DEG, "deg"),
            ("theta", joint.theta, limits::ANGLE_DEG, "deg"),
            ("d", joint.d, limits::LENGTH_MM, "mm"),
        ] {
            if !(v.is_finite() && v.abs() <= limit) {
                return Err(RobotImportError::UrdfJoint {
                    path: path.to_path_buf(),
                    joint: name.clone(),
                    message: format!(
                        "its modified-DH {key} comes out as {} {unit}, beyond the plausible {limit} {unit}: check the joint's origin and axis",
                        show(v)
                    ),
                });
            }
        }
    }
    for (what, t) in [("base", &mdh.base), ("flange", &mdh.flange)] {
        let n = t.translation.vector.norm();
        if !(n.is_finite() && n <= limits::LENGTH_MM) {
            return Err(RobotImportError::UrdfTree {
                path: path.to_path_buf(),
                message: format!(
                    "the {what} transform of the chain is {} mm long, beyond the plausible {} mm",
                    show(n),
                    limits::LENGTH_MM
                ),
            });
        }
    }
    Ok(())
}

/// `true` for a revolute or continuous joint, `false` for a fixed one, an
/// error for every other type and for mimic joints.
fn revolute_kind(joint: &urdf_rs::Joint, path: &Path) -> Result<bool, RobotImportError> {
    use urdf_rs::JointType;
    let kind = match joint.joint_type {
        JointType::Fixed => return Ok(false),
        JointType::Revolute | JointType::Continuous => {
            if let Some(mimic) = &joint.mimic {
                return Err(joint_error(
                    path,
                    joint,
                    format!(
                        "mimics joint `{}`: coupled joints are not supported",
                        mimic.joint
                    ),
                ));
            }
            return Ok(true);
        }
        JointType::Prismatic => "prismatic",
        JointType::Floating => "floating",
        JointType::Planar => "planar",
        JointType::Spherical => "spherical",
    };
    Err(joint_error(
        path,
        joint,
        format!(
            "{kind} joints are not supported: the model has revolute joints only \
             (revolute and continuous move, fixed ones are folded in)"
        ),
    ))
}

/// The joint's `<axis>` as a unit vector in the joint frame.
fn unit_axis(joint: &urdf_rs::Joint, path: &Path) -> Result<Vector3<f64>, RobotImportError> {
    let [x, y, z] = joint.axis.xyz.0;
    let v = Vector3::new(x, y, z);
    // Scaled first, so that huge components do not overflow the norm.
    let largest = v.amax();
    let v = if largest > 0.0 && largest.is_finite() {
        v / largest
    } else {
        v
    };
    let norm = v.norm();
    if norm.is_finite() && norm > 1e-12 {
        Ok(v / norm)
    } else {
        Err(joint_error(
            path,
            joint,
            format!("axis xyz=\"{x} {y} {z}\" has no direction"),
        ))
    }
}

/// The joint's limits in degrees: `<limit lower upper>` of a revolute
/// joint, infinite for a continuous one.
fn joint_limit(joint: &urdf_rs::Joint, path: &Path) -> Result<JointLimit, RobotImportError> {
    if joint.joint_type == urdf_rs::JointType::Continuous {
        return Ok(JointLimit {
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        });
    }
    let (lower, upper) = (joint.limit.lower, joint.limit.upper);
    if lower < upper {
        return Ok(JointLimit {
            min: lower.to_degrees(),
            max: upper.to_degrees(),
        });
    }
    Err(joint_error(
        path,
        joint,
        format!(
            "limit lower={lower} is not below upper={upper} (a revolute joint needs \
             <limit lower=\"..\" upper=\"..\"> in radians)"
        ),
    ))
}

/// A URDF `<origin xyz rpy>` as an isometry in mm: translation `xyz`·1000,
/// rotation `Rz(yaw)·Ry(pitch)·Rx(roll)` (fixed axes roll, pitch, yaw).
fn origin_mm(origin: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = origin.xyz.0;
    let [roll, pitch, yaw] = origin.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x * 1000.0, y * 1000.0, z * 1000.0),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

/// A frame in the root: origin and orthonormal x, z axes.
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// Origin, mm.
    origin: Vector3<f64>,
    /// Unit x axis.
    x: Vector3<f64>,
    /// Unit z axis, normal to `x`.
    z: Vector3<f64>,
}

impl Frame {
    /// The frame's rotation (columns x, y, z).
    fn rotation(&self) -> Rotation3<f64> {
        Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
            self.x,
            self.z.cross(&self.x),
            self.z,
        ]))
    }

    /// Root → frame as an isometry.
    fn isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::from(self.origin),
            UnitQuaternion::from_rotation_matrix(&self.rotation()),
        )
    }
}

/// The MDH model of a chain: joints plus base and flange transforms.
struct MdhChain {
    /// MDH joints, deg and mm.
    joints: Vec<Joint>,
    /// Root → frame 0.
    base: Isometry3<f64>,
    /// Frame `n` → tip.
    flange: Isometry3<f64>,
}

/// The MDH frames and parameters of the axis lines `axes` ending in the
/// tip pose `tip` (module docs). No axes: no joints, `F` = the tip pose.
fn mdh_from_axes(axes: &[AxisLine], tip: &Isometry3<f64>) -> MdhChain {
    let Some(first) = axes.first() else {
        return MdhChain {
            joints: Vec::new(),
            base: Isometry3::identity(),
            flange: *tip,
        };
    };
    // Frame 0: the axes of frame 1, at the foot of the perpendicular from
    // the root origin onto axis 1.
    let mut land = foot(first, &Vector3::zeros());
    let mut x_ref = perp_unit(&Vector3::x(), &first.dir)
        .or_else(|| perp_unit(&Vector3::y(), &first.dir))
        .unwrap_or_else(|| any_perp(&first.dir));
    let mut frames = Vec::with_capacity(axes.len());
    for (i, axis) in axes.iter().enumerate() {
        let (frame, next_land) = match axes.get(i + 1) {
            Some(next) => frame_towards(axis, next, &land, &x_ref),
            None => (last_frame(axis, tip), land),
        };
        frames.push((frame, land));
        x_ref = frame.x;
        land = next_land;
    }
    let mut prev = frames.first().map_or_else(
        || last_frame(first, tip),
        |(frame, land)| Frame {
            origin: *land,
            ..*frame
        },
    );
    let base = prev.isometry();
    let mut joints = Vec::with_capacity(axes.len());
    for (frame, land) in &frames {
        joints.push(link_params(&prev, land, frame));
        prev = *frame;
    }
    MdhChain {
        joints,
        base,
        flange: prev.isometry().inverse() * tip,
    }
}

/// Frame `i` on `axis` given the next axis, the point `land` where
/// `x_{i-1}` meets `axis`, and `x_ref` (the previous x, for sign choices).
/// Returns the frame and the point where its x meets `next`.
fn frame_towards(
    axis: &AxisLine,
    next: &AxisLine,
    land: &Vector3<f64>,
    x_ref: &Vector3<f64>,
) -> (Frame, Vector3<f64>) {
    let z = axis.dir;
    let normal = z.cross(&next.dir);
    if normal.norm() < PARALLEL_SIN {
        // (Nearly) parallel: stay at `land` (d_i = 0), go normal to z_i to
        // where the plane through `land` meets the next axis.
        let t = (land - next.point).dot(&z) / next.dir.dot(&z);
        let hit = next.point + next.dir * t;
        let x = perp_unit(&(hit - land), &z)
            .filter(|_| (hit - land).norm() > INTERSECT_MM)
            .or_else(|| perp_unit(x_ref, &z))
            .unwrap_or_else(|| any_perp(&z));
        let frame = Frame {
            origin: *land,
            x,
            z,
        };
        return (frame, hit);
    }
    let (on_axis, on_next) = closest_points(axis, next);
    let gap = on_next - on_axis;
    let mut x = normal.normalize();
    let toward = if gap.norm() > INTERSECT_MM {
        gap
    } else {
        *x_ref
    };
    if x.dot(&toward) < 0.0 {
        x = -x;
    }
    let a = gap.dot(&x);
    let frame = Frame {
        origin: on_axis,
        x,
        z,
    };
    (frame, on_axis + x * a)
}

/// The last frame: on `axis` at the foot of the perpendicular from the
/// tip's origin, x along the tip's x (or y when the tip's x is within 30°
/// of the axis) made normal to the axis.
fn last_frame(axis: &AxisLine, tip: &Isometry3<f64>) -> Frame {
    let z = axis.dir;
    let tip_x = tip.rotation * Vector3::x();
    let tip_y = tip.rotation * Vector3::y();
    let x = if (tip_x - z * tip_x.dot(&z)).norm() >= 0.5 {
        perp_unit(&tip_x, &z)
    } else {
        perp_unit(&tip_y, &z)
    }
    .unwrap_or_else(|| any_perp(&z));
    Frame {
        origin: foot(axis, &tip.translation.vector),
        x,
        z,
    }
}

/// The MDH parameters taking frame `prev` to `cur`, where `land` is the
/// point on `cur`'s axis that `Tx(a)` reaches (deg, mm):
/// `prev⁻¹·cur = Rx(alpha)·Tx(a)·Ry(beta)·Rz(theta)·Tz(d)`.
fn link_params(prev: &Frame, land: &Vector3<f64>, cur: &Frame) -> Joint {
    let rot = prev.rotation();
    let (xp, yp, zp) = (rot * Vector3::x(), rot * Vector3::y(), rot * Vector3::z());
    let z = cur.z;
    let alpha = (-z.dot(&yp)).atan2(z.dot(&zp));
    let beta = z.dot(&xp).atan2(z.dot(&yp).hypot(z.dot(&zp)));
    let beta = if beta.abs() < BETA_NOISE { 0.0 } else { beta };
    let mid = rot
        * Rotation3::from_axis_angle(&Vector3::x_axis(), alpha)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), beta);
    let theta = cur
        .x
        .dot(&(mid * Vector3::y()))
        .atan2(cur.x.dot(&(mid * Vector3::x())));
    Joint {
        alpha: alpha.to_degrees(),
        a: (land - prev.origin).dot(&xp),
        beta: beta.to_degrees(),
        theta: theta.to_degrees(),
        d: (cur.origin - land).dot(&z),
    }
}

/// The point of `axis` nearest to `p`.
fn foot(axis: &AxisLine, p: &Vector3<f64>) -> Vector3<f64> {
    axis.point + axis.dir * (p - axis.point).dot(&axis.dir)
}

/// The nearest points of two non-parallel lines (on `a`, on `b`).
fn closest_points(a: &AxisLine, b: &AxisLine) -> (Vector3<f64>, Vector3<f64>) {
    let w = a.point - b.point;
    let c = a.dir.dot(&b.dir);
    let (da, db) = (a.dir.dot(&w), b.dir.dot(&w));
    let den = 1.0 - c * c;
    let s = (c * db - da) / den;
    let t = (db - c * da) / den;
    (a.point + a.dir * s, b.point + b.dir * t)
}

/// `v` made normal to the unit vector `z` and normalised, if it is not
/// (nearly) along `z`.
fn perp_unit(v: &Vector3<f64>, z: &Vector3<f64>) -> Option<Vector3<f64>> {
    let p = v - z * v.dot(z);
    let n = p.norm();
    (n > 1e-9).then(|| p / n)
}

/// Some unit vector normal to the unit vector `z`.
fn any_perp(z: &Vector3<f64>) -> Vector3<f64> {
    let helper = if z.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    z.cross(&helper).normalize()
}
