//! `spherecal plan --mount fixed`: poses for a fixed sensor (a tracker's
//! line of sight to a target on the tool) over a workspace box
//! ([`plan_fixed`](crate::engine::tools::plan::fixed::plan_fixed)), written
//! as the joint log the robot runs and `import --mount fixed` reads.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use crate::cli::CliError;
use crate::cli::import::MountArg;
use crate::cli::plan::PlanArgs;
use crate::engine::base::cell::workspace::Workspace;
use crate::engine::base::robot::{self, RobotChoice};
use crate::engine::base::session::Use;
use crate::engine::files::format;
use crate::engine::tools::plan::fixed::{FixedPlanRequest, fixed_plan_csv, plan_fixed};

/// Candidates drawn per planned pose.
const CANDIDATES_PER_POSE: usize = 30;

/// `spherecal plan`: a fixed sensor's plan here, anything else by
/// [`crate::cli::plan::run`].
///
/// # Errors
/// As the plan that runs.
pub fn dispatch(args: &PlanArgs) -> Result<(), CliError> {
    if args.mount == MountArg::Fixed {
        run(args)
    } else {
        crate::cli::plan::run(args)
    }
}

fn run(args: &PlanArgs) -> Result<(), CliError> {
    let Some(sensor) = args.sensor_at else {
        return Err(CliError::input(
            "--mount fixed needs --sensor-at X,Y,Z: where the sensor stands (mm, base frame)",
        ));
    };
    let (Some(preset), Some(choice)) = (
        robot::preset(&args.robot),
        RobotChoice::from_key(&args.robot),
    ) else {
        return Err(CliError::input(format!(
            "--mount fixed plans for a preset robot (--robot {}); {} is not one",
            super::preset_keys(),
            args.robot
        )));
    };
    let workspace = Workspace::for_robot(choice);
    let centre = Vector3::from_fn(|k, _| f64::midpoint(workspace.min[k], workspace.max[k]));
    let (box_min, box_max) = match args.box_size {
        Some(size) => (
            [0, 1, 2].map(|k| centre[k] - size[k] / 2.0),
            [0, 1, 2].map(|k| centre[k] + size[k] / 2.0),
        ),
        None => (workspace.min, workspace.max),
    };
    let position = Vector3::from(sensor);
    let look = centre - position;
    if look.norm() < 1.0 {
        return Err(CliError::input(
            "--sensor-at is in the middle of the workspace box: the sensor must look at it from outside",
        ));
    }
    let base_from_sensor = Isometry3::from_parts(
        Translation3::from(position),
        UnitQuaternion::face_towards(&look, &Vector3::z()),
    );
    let n_identify = args.identify_stations * args.identify_poses;
    let n_validate = args.validate_stations * args.validate_poses;
    let req = FixedPlanRequest {
        preset,
        base_from_sensor,
        target: Vector3::from(args.target),
        target_normal: Vector3::z(),
        cone_deg: args.cone,
        reach_mm: args.reach,
        box_min,
        box_max,
        n_identify,
        n_validate,
        candidates: CANDIDATES_PER_POSE * (n_identify + n_validate),
        seed: args.seed,
    };
    let poses = plan_fixed(&req).map_err(|e| CliError::input(e.to_string()))?;
    if let Some(csv) = &args.csv {
        format::write_atomic(csv, fixed_plan_csv(&poses).as_bytes())
            .map_err(|e| CliError::from_file(&e, false))?;
    }
    if !args.quiet {
        let count = |u: Use| poses.iter().filter(|p| p.usage == u).count();
        let seen =
            |q: &[f64]| (req.preset.robot.base_from_flange(q) * Point3::from(req.target)).coords;
        let spread = poses.iter().map(|p| seen(&p.joints)).fold(
            (
                Vector3::repeat(f64::INFINITY),
                Vector3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), x| (lo.inf(&x), hi.sup(&x)),
        );
        sayln!(
            "planned {} poses for a fixed sensor at ({}, {}, {}) mm: {} identify (D-optimal of {} candidates), {} validate; the target faces the sensor within {}°",
            poses.len(),
            sensor[0],
            sensor[1],
            sensor[2],
            count(Use::Identify),
            req.candidates,
            count(Use::Validate),
            args.cone
        );
        sayln!(
            "the target spans x {:.0}…{:.0}, y {:.0}…{:.0}, z {:.0}…{:.0} mm (base frame)",
            spread.0.x,
            spread.1.x,
            spread.0.y,
            spread.1.y,
            spread.0.z,
            spread.1.z
        );
        if let Some(csv) = &args.csv {
            sayln!("wrote {} (id,use,j1..jn, deg)", csv.display());
        }
    }
    Ok(())
}
