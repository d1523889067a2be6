//! Ground truth: joints from `gt/trans.json` (PARIS / ArtGS format) and per-part meshes.
//!
//! `{"trans_info": [ {"axis": {"o": [x,y,z], "d": [x,y,z]}, "type": "rotate"|"translate",
//! "rotate"|"translate": {"l": start, "r": end}}, ... ]}`, one entry per movable part in part order; PARIS writes
//! a single object instead of a list. Angles are degrees, translations metres.

use glam::{Affine3A, Quat, Vec3};
use serde_json::{Value, json};

use super::FileSet;
use super::error::{DataError, Errors};
use super::finite::{ensure_finite, point_values};
use super::json::{Json, f32_array, f32_value, join};
use super::ply::{PlyFormat, TriMesh};
use super::{GT_TRANS_PATH, State};

/// Joint type of a movable part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rotation about an axis (`"rotate"`; values in degrees).
    Revolute,
    /// Translation along an axis (`"translate"`; values in metres).
    Prismatic,
}

impl JointKind {
    /// The `type` string (and motion key) used in `trans.json`.
    pub(crate) fn trans_name(self) -> &'static str {
        match self {
            JointKind::Revolute => "rotate",
            JointKind::Prismatic => "translate",
        }
    }
}

/// A ground-truth joint, values as in the file.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GtJoint {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// A point on the axis (`axis.o`), metres.
    pub origin: Vec3,
    /// Axis direction (`axis.d`) as given (not necessarily unit length; never zero).
    pub direction: Vec3,
    /// Joint value at the start state (`l`): degrees or metres.
    pub start: f32,
    /// Joint value at the end state (`r`): degrees or metres.
    pub end: f32,
}

impl GtJoint {
    /// Motion from start to end (`r - l`): degrees or metres.
    pub fn motion(&self) -> f32 {
        self.end - self.start
    }

    /// Unit axis direction.
    pub fn unit_direction(&self) -> Vec3 {
        self.direction.normalize_or_zero()
    }

    /// Motion from start to end in URDF units: radians for a revolute joint, metres for a
    /// prismatic one.
    pub fn urdf_motion(&self) -> f32 {
        match self.kind {
            JointKind::Revolute => self.motion().to_radians(),
            JointKind::Prismatic => self.motion(),
        }
    }

    /// Where a part goes when its joint moves by `value` (URDF units) from the start state: a
    /// rotation about the axis through its origin, or a shift along it.
    pub fn pose_at(&self, value: f32) -> Affine3A {
        let d = self.unit_direction();
        match self.kind {
            JointKind::Revolute => {
                let r = Affine3A::from_quat(Quat::from_axis_angle(d, value));
                Affine3A::from_translation(self.origin)
                    * r
                    * Affine3A::from_translation(-self.origin)
            }
            JointKind::Prismatic => Affine3A::from_translation(d * value),
        }
    }
}

/// Ground-truth meshes of one state.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GtMeshes {
    /// The static base (part 0).
    pub static_part: TriMesh,
    /// Movable parts 1..=K, in part order.
    pub movable: Vec<TriMesh>,
}

/// `gt/{state}/{state}_static_rotate.ply`
pub(crate) fn static_mesh_path(state: State) -> String {
    format!("gt/{0}/{0}_static_rotate.ply", state.name())
}

/// `gt/{state}/{state}_dynamic_{i}_rotate.ply` (i from 0 for the first movable part)
pub(crate) fn movable_mesh_path(state: State, i: usize) -> String {
    format!("gt/{0}/{0}_dynamic_{i}_rotate.ply", state.name())
}

/// PARIS's single-part name, `gt/{state}/{state}_dynamic_rotate.ply`, read as movable part 0.
pub(crate) fn single_movable_mesh_path(state: State) -> String {
    format!("gt/{0}/{0}_dynamic_rotate.ply", state.name())
}

fn parse_entry(j: Json<'_>, field: &str, v: &Value) -> Result<GtJoint, DataError> {
    let obj = j.object(field, v)?;
    let axis_field = join(field, "axis");
    let axis = j.object(
        &axis_field,
        j.required(
            field,
            obj,
            "axis",
            "an object {\"o\": [x,y,z], \"d\": [x,y,z]}",
        )?,
    )?;
    let o = j.numbers::<3>(
        &join(&axis_field, "o"),
        j.required(&axis_field, axis, "o", "the axis origin [x, y, z]")?,
    )?;
    let d_field = join(&axis_field, "d");
    let d = j.numbers::<3>(
        &d_field,
        j.required(&axis_field, axis, "d", "the axis direction [x, y, z]")?,
    )?;
    let direction = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    if direction.length() <= 1e-9 || !direction.is_finite() {
        return Err(j.err(
            &d_field,
            format!("expected a non-zero, finite axis direction, found {direction}"),
        ));
    }
    let type_field = join(field, "type");
    let ty = j.string(
        &type_field,
        j.required(field, obj, "type", "\"rotate\" or \"translate\"")?,
    )?;
    let kind = match ty {
        "rotate" => JointKind::Revolute,
        "translate" => JointKind::Prismatic,
        other => {
            return Err(j.err(
                &type_field,
                format!("expected \"rotate\" or \"translate\", found \"{other}\""),
            ));
        }
    };
    let key = kind.trans_name();
    let motion_field = join(field, key);
    let motion = j.object(
        &motion_field,
        j.required(
            field,
            obj,
            key,
            &format!("the motion {{\"l\": start, \"r\": end}} of a \"{key}\" joint"),
        )?,
    )?;
    let l = j.number(
        &join(&motion_field, "l"),
        j.required(&motion_field, motion, "l", "the start value")?,
    )?;
    let r = j.number(
        &join(&motion_field, "r"),
        j.required(&motion_field, motion, "r", "the end value")?,
    )?;
    Ok(GtJoint {
        kind,
        origin: Vec3::new(o[0] as f32, o[1] as f32, o[2] as f32),
        direction,
        start: l as f32,
        end: r as f32,
    })
}

/// Reads `gt/trans.json`; every bad entry is reported. `None` if anything was wrong.
pub(crate) fn parse_trans(bytes: &[u8], errs: &mut Errors) -> Option<Vec<GtJoint>> {
    let j = Json {
        file: GT_TRANS_PATH,
    };
    let root = errs.keep(super::json::parse(GT_TRANS_PATH, bytes))?;
    let obj = errs.keep(j.object("", &root))?;
    let info = errs.keep(j.required(
        "",
        obj,
        "trans_info",
        "a list of joints (or one joint object)",
    ))?;
    let before = errs.len();
    let joints: Vec<GtJoint> = match info {
        // PARIS: a single joint object.
        Value::Object(_) => errs
            .keep(parse_entry(j, "trans_info", info))
            .into_iter()
            .collect(),
        Value::Array(list) => list
            .iter()
            .enumerate()
            .filter_map(|(i, v)| errs.keep(parse_entry(j, &format!("trans_info[{i}]"), v)))
            .collect(),
        other => {
            errs.push(j.err(
                "trans_info",
                format!(
                    "expected a list of joints or a joint object, found {}",
                    super::json::describe(other)
                ),
            ));
            return None;
        }
    };
    (errs.len() == before).then_some(joints)
}

fn entry_json(joint: &GtJoint) -> Value {
    let mut entry = json!({
        "axis": { "o": f32_array(&joint.origin.to_array()), "d": f32_array(&joint.direction.to_array()) },
        "type": joint.kind.trans_name(),
    });
    if let Some(map) = entry.as_object_mut() {
        map.insert(
            joint.kind.trans_name().into(),
            json!({ "l": f32_value(joint.start), "r": f32_value(joint.end) }),
        );
    }
    entry
}

/// Writes `gt/trans.json` with a `trans_info` list.
pub(crate) fn write_trans(joints: &[GtJoint]) -> Vec<u8> {
    let list: Vec<Value> = joints.iter().map(entry_json).collect();
    serde_json::to_vec_pretty(&json!({ "trans_info": list })).unwrap_or_default()
}

/// Writes a PARIS-style `trans.json` whose `trans_info` is the single joint object.
pub(crate) fn write_trans_single(joint: &GtJoint) -> Vec<u8> {
    serde_json::to_vec_pretty(&json!({ "trans_info": entry_json(joint) })).unwrap_or_default()
}

/// Part count implied by the ground-truth joints, the largest part id seen and the GT mesh count: one rule for
/// reader and writer. With `gt/trans.json` it is 1 + joints; otherwise 1 + the largest id or mesh index.
pub(crate) fn implied_num_parts(
    joints: Option<&[GtJoint]>,
    max_id: Option<i16>,
    meshes: &[Option<GtMeshes>; 2],
) -> usize {
    let max_movable_meshes = meshes
        .iter()
        .flatten()
        .map(|m| m.movable.len())
        .max()
        .unwrap_or(0);
    match joints {
        Some(j) => 1 + j.len(),
        None => {
            let from_ids = max_id.map_or(0, |m| usize::try_from(i32::from(m) + 1).unwrap_or(0));
            from_ids.max(1 + max_movable_meshes)
        }
    }
}

/// Writes `gt/trans.json` (when there are joints) and each state's part meshes as binary PLY into `out`.
pub(crate) fn write_ground_truth(
    joints: Option<&[GtJoint]>,
    meshes: &[Option<GtMeshes>; 2],
    out: &mut FileSet,
) -> Result<(), DataError> {
    if let Some(joints) = joints {
        for (i, j) in joints.iter().enumerate() {
            let values = point_values(&[j.origin, j.direction])
                .chain([j.start, j.end])
                .collect::<Vec<_>>();
            ensure_finite(GT_TRANS_PATH, &format!("trans_info[{i}]"), values)?;
        }
        out.insert(GT_TRANS_PATH.into(), write_trans(joints));
    }
    for state in State::ALL {
        if let Some(m) = &meshes[state.index()] {
            let mut ply = |path: String, mesh: &TriMesh| -> Result<(), DataError> {
                ensure_finite(&path, "vertex", point_values(&mesh.positions))?;
                out.insert(path, mesh.to_ply(PlyFormat::BinaryLittleEndian));
                Ok(())
            };
            ply(static_mesh_path(state), &m.static_part)?;
            for (i, mesh) in m.movable.iter().enumerate() {
                ply(movable_mesh_path(state, i), mesh)?;
            }
        }
    }
    Ok(())
}
