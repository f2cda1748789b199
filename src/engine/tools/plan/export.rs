//! A plan's exports: the joint log CSV that `spherecal import` reads (and
//! `spherecal simulate --plan` reads back), and robot programs for the
//! controllers of [`PROGRAMS`], one [`render_program`] arm per controller.

use std::fmt::Write as _;

use nalgebra::Vector3;

use super::{Plan, PlanError};
use crate::engine::base::cell::joint_log;
use crate::engine::base::robot::controller::Controller;
use crate::engine::base::session::Use;
use crate::engine::files::table::{Table, side_cell};
use crate::engine::tools::simulate::PlanPose;

/// The plan as a joint log CSV that `spherecal import` reads: header
/// `id,station,use,side,j1..jn,x,y,z,q1,q2,q3,q4` (joints deg; the nominal
/// model's ABB flange pose, mm and quaternion w, x, y, z, so that
/// `--flange-poses ABB` checks it), then `sphere_x,sphere_y,sphere_z` (the
/// station, base frame, mm) and `centre_x,centre_y,centre_z` (the planned
/// sensor-frame centre, mm), which the import ignores. `#` lines before
/// the header describe the plan.
#[must_use]
pub fn plan_csv(plan: &Plan) -> String {
    let comments = [
        format!(
            "spherecal plan: {}, {} poses, sphere diameter {} mm, cut angle ±{}°",
            plan.robot.name,
            plan.poses.len(),
            plan.diameter,
            plan.cut_angle
        ),
        "joints in deg; x,y,z,q1..q4: nominal flange pose (mm, ABB quaternion w,x,y,z); sphere_*: station (base, mm); centre_*: planned sphere centre (sensor, mm)".to_string(),
    ];
    let rows: Vec<joint_log::Row> = plan
        .poses
        .iter()
        .map(|p| {
            let s = plan
                .station(&p.station)
                .map_or_else(Vector3::zeros, |s| s.position);
            let c = p.centre_in_sensor;
            joint_log::Row {
                id: &p.id,
                station: &p.station,
                usage: p.usage,
                side: p.side,
                joints: &p.joints,
                flange: p.base_from_flange,
                extra: vec![
                    format!("{:.6}", s.x),
                    format!("{:.6}", s.y),
                    format!("{:.6}", s.z),
                    format!("{:.9}", c.x),
                    format!("{:.9}", c.y),
                    format!("{:.9}", c.z),
                ],
            }
        })
        .collect();
    joint_log::write(
        &comments,
        plan.robot.dof(),
        &[
            "sphere_x", "sphere_y", "sphere_z", "centre_x", "centre_y", "centre_z",
        ],
        &rows,
    )
}

/// Reads the poses of a plan CSV ([`plan_csv`]'s layout; columns found by
/// name, case-insensitively; `#` and blank lines skipped) for
/// [`simulate::simulate_plan`](crate::engine::tools::simulate::simulate_plan). The joint columns are `j1`, `j2`, … as
/// many as the header has.
///
/// # Errors
/// [`PlanError::Csv`] naming the line and the column.
pub fn read_plan_csv(text: &str) -> Result<Vec<PlanPose>, PlanError> {
    let table = Table::parse(text).map_err(|e| PlanError::Csv {
        line: e.line,
        message: e.message,
    })?;
    let header_line = table.header_line;
    let header = &table.header;
    let column = |name: &str| {
        table.column(name).ok_or_else(|| PlanError::Csv {
            line: header_line,
            message: table.no_column(name),
        })
    };
    let (id, station, usage, side) = (
        column("id")?,
        column("station")?,
        column("use")?,
        column("side")?,
    );
    let joints: Vec<usize> = (1..)
        .map_while(|k| table.column(&format!("j{k}")))
        .collect();
    let centre = [
        column("centre_x")?,
        column("centre_y")?,
        column("centre_z")?,
    ];
    let mut out = Vec::new();
    for (line, fields) in &table.rows {
        let line = *line;
        let fail = |message: String| PlanError::Csv { line, message };
        let number = |c: usize| -> Result<f64, PlanError> {
            fields[c]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    fail(format!(
                        "column `{}`: `{}` is not a finite number",
                        header[c], fields[c]
                    ))
                })
        };
        let usage = Use::parse(&fields[usage]).ok_or_else(|| {
            fail(format!(
                "`{}` is not translation, rotation, identify or validate",
                fields[usage]
            ))
        })?;
        // A plan gives every pose its side: blank is no side.
        let Ok(Some(side)) = side_cell(&fields[side]) else {
            return Err(fail(format!("side `{}` is not +1 or -1", fields[side])));
        };
        out.push(PlanPose {
            id: fields[id].clone(),
            station: fields[station].clone(),
            usage,
            side,
            joints: joints
                .iter()
                .map(|&c| number(c))
                .collect::<Result<_, _>>()?,
            centre_in_sensor: [number(centre[0])?, number(centre[1])?, number(centre[2])?],
        });
    }
    if out.is_empty() {
        return Err(PlanError::Csv {
            line: header_line,
            message: "no poses after the header".to_owned(),
        });
    }
    Ok(out)
}

/// The controllers a plan is exported to as a program. To add one (KUKA
/// KRL, FANUC TP): its arm in [`render_program`] writing the program from
/// [`Plan::poses`] (joint targets in deg, in plan order; ids and stations
/// for comments), then list it here; the command line's `--program
/// KEY=FILE` ([`Controller::key`]) picks it up.
pub const PROGRAMS: [Controller; 2] = [Controller::Abb, Controller::Ur];

/// The controller of [`PROGRAMS`] whose program key is `key`.
#[must_use]
pub fn parse_program(key: &str) -> Option<Controller> {
    PROGRAMS.into_iter().find(|c| c.key() == key)
}

/// The controller of a robot (by its model name) when a plan can be
/// exported to it as a program; `None` otherwise (the plan CSV still
/// works).
#[must_use]
pub fn program_controller(robot_name: &str) -> Option<Controller> {
    Controller::for_robot(robot_name).filter(|c| PROGRAMS.contains(c))
}

/// The plan as `controller`'s program.
///
/// # Errors
/// [`PlanError::NoProgram`] for a controller not in [`PROGRAMS`].
pub fn render_program(controller: Controller, plan: &Plan) -> Result<String, PlanError> {
    match controller {
        Controller::Abb => Ok(rapid_module(plan)),
        Controller::Ur => Ok(ur_script(plan)),
        other @ (Controller::Kuka | Controller::Fanuc) => Err(PlanError::NoProgram(other)),
    }
}

/// A warning when the plan's robot, by its name, is another maker's than
/// `controller`'s: its controller does not run that program (a RAPID
/// module for a UR5e). `None` when they match or the name names no maker.
#[must_use]
pub fn other_maker_warning(controller: Controller, plan: &Plan) -> Option<String> {
    let own = Controller::for_robot(&plan.robot.name)?;
    (own != controller).then(|| {
        format!(
            "warning: the robot is {}, not a robot of {}: its controller does not run a {}{}",
            plan.robot.name,
            controller.name(),
            controller.label(),
            if super::PROGRAMS.contains(&own) {
                format!(" (a {} is what it runs)", own.label())
            } else {
                String::new()
            }
        )
    })
}

/// The comment lines every controller program starts with (robot, poses,
/// sphere, each station's position), each line after `lead` (the
/// language's indent and comment mark); `units` says the joints' unit.
fn header_comments(out: &mut String, plan: &Plan, lead: &str, units: &str) {
    let _ = writeln!(
        out,
        "{lead}Generated by spherecal plan: {}, {} poses at {} stations.",
        plan.robot.name,
        plan.poses.len(),
        plan.stations.len()
    );
    let _ = writeln!(
        out,
        "{lead}Sphere diameter {} mm, laser plane at +/-{} deg on the sphere. {units}",
        plan.diameter, plan.cut_angle
    );
    for s in &plan.stations {
        let _ = writeln!(
            out,
            "{lead}Station {}: sphere at [{:.1}, {:.1}, {:.1}] mm (base frame).",
            s.id, s.position.x, s.position.y, s.position.z
        );
    }
}

/// `text` with every non-ASCII character replaced by `?` (controllers
/// read ASCII or ISO-8859-1).
fn ascii(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_ascii() { c } else { '?' })
        .collect()
}

/// RAPID module name of the export.
pub const RAPID_MODULE: &str = "SpherecalPlan";

/// The plan as an ABB RAPID module: one `CONST jointtarget jt_<id>` per
/// pose (joints deg to 4 decimals, external axes unused `9E9`), and a
/// `main` that visits them in plan order with `MoveAbsJ … fine, tool0`,
/// stops with a message when the sphere has to be moved to the next
/// station, and calls the `Measure` hook at every pose (edit it to trigger
/// the sensor and log the joints). Plain ASCII (controllers read
/// ISO-8859-1).
#[must_use]
pub fn rapid_module(plan: &Plan) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "MODULE {RAPID_MODULE}");
    header_comments(&mut out, plan, "    ! ", "Joint targets in deg.");
    let _ = writeln!(out);
    let _ = writeln!(out, "    PERS speeddata vPlan := [200, 100, 5000, 1000];");
    for p in &plan.poses {
        let joints: Vec<String> = p.joints.iter().map(|q| format!("{q:.10}")).collect();
        let _ = writeln!(
            out,
            "    CONST jointtarget jt_{} := [[{}], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]]; ! station {}, {}, side {:+}",
            p.id,
            joints.join(", "),
            p.station,
            p.usage.as_str(),
            p.side
        );
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "    PROC main()");
    let mut station = "";
    for p in &plan.poses {
        if p.station != station {
            station = &p.station;
            let _ = writeln!(out, "        ! --- station {station} ---");
            let _ = writeln!(
                out,
                "        TPWrite \"Place the sphere at station {station}, then press Start\";"
            );
            let _ = writeln!(out, "        Stop;");
        }
        let _ = writeln!(out, "        MoveAbsJ jt_{}, vPlan, fine, tool0;", p.id);
        let _ = writeln!(out, "        Measure \"{}\", \"{}\";", p.id, p.station);
    }
    let _ = writeln!(out, "    ENDPROC");
    let _ = writeln!(out);
    let _ = writeln!(out, "    PROC Measure(string id, string station)");
    let _ = writeln!(
        out,
        "        ! Hook: trigger the laser-stripe sensor here and log id, station and CJointT() (e.g. SetDO, WaitDI)."
    );
    let _ = writeln!(out, "        WaitTime 0.5;");
    let _ = writeln!(out, "    ENDPROC");
    let _ = writeln!(out, "ENDMODULE");
    ascii(&out)
}

/// The plan as a URScript program for a Universal Robots controller: one
/// `movej` per pose (joints in rad, plan order), a blocking `popup` when
/// the sphere has to be moved to the next station, and a `measure` hook
/// at every pose (edit it to trigger the sensor and log the joints).
/// Plain ASCII.
#[must_use]
pub fn ur_script(plan: &Plan) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "def spherecal_plan():");
    header_comments(&mut out, plan, "  # ", "Joints in rad.");
    let _ = writeln!(out, "  def measure(id, station):");
    let _ = writeln!(
        out,
        "    # Hook: trigger the laser-stripe sensor here and log id, station and get_actual_joint_positions()."
    );
    let _ = writeln!(out, "    sleep(0.5)");
    let _ = writeln!(out, "  end");
    let mut station = "";
    for p in &plan.poses {
        if p.station != station {
            station = &p.station;
            let _ = writeln!(out, "  # --- station {station} ---");
            let _ = writeln!(
                out,
                "  popup(\"Place the sphere at station {station}, then press Continue\", \"spherecal\", blocking=True)"
            );
        }
        let joints: Vec<String> = p
            .joints
            .iter()
            .map(|q| format!("{:.12}", q.to_radians()))
            .collect();
        let _ = writeln!(
            out,
            "  movej([{}], a=0.5, v=0.25)  # {}, station {}, {}, side {:+}",
            joints.join(", "),
            p.id,
            p.station,
            p.usage.as_str(),
            p.side
        );
        let _ = writeln!(out, "  measure(\"{}\", \"{}\")", p.id, p.station);
    }
    let _ = writeln!(out, "end");
    ascii(&out)
}
