//! Per-object evaluation: joint matching, the joint metrics averaged per object, CD-s and CD-m.
//!
//! Per-object averages follow the peers: Axis Ang and Part Motion over all matched joints (Part Motion mixes
//! degrees and metres in the paper's single column; the revolute and prismatic means are reported apart as
//! well), Axis Pos over matched pairs whose GT joint is revolute. Benchmark columns then average these
//! per-object values over objects (see [`super::tables`]).

use super::EvalError;
use super::chamfer::{ChamferDistance, ChamferOptions, MeshFault, chamfer_meshes};
use super::joints::{JointPairMetrics, match_joints};
use crate::data::{Dataset, GtJoint, GtMeshes, JointKind, State, TriMesh};
use crate::fit::object::ObjectFit;

/// Settings of [`evaluate_object`].
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct EvalOptions {
    /// Surface sampling of the Chamfer distances.
    pub chamfer: ChamferOptions,
}

/// Chamfer distance of one matched movable part.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PartChamfer {
    /// Predicted movable part (= predicted joint index).
    pub pred: usize,
    /// GT movable part (= GT joint index).
    pub gt: usize,
    /// The distance in both conventions.
    pub chamfer: ChamferDistance,
}

/// All metrics of one object; the unit of the per-object JSON and of the tables.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ObjectMetrics {
    /// Object identifier.
    pub id: String,
    /// Category (e.g. `StorageFurniture`), for the per-category table.
    pub category: String,
    /// Part count of the GT object: 1 (static base) + movable parts; decides the table bucket.
    pub part_count: usize,
    /// Predicted movable parts (= predicted joints).
    pub predicted_joints: usize,
    /// Matched joint pairs and their errors, in GT order.
    pub joints: Vec<JointPairMetrics>,
    /// Predicted joints without a GT joint.
    pub unmatched_pred: Vec<usize>,
    /// GT joints without a prediction.
    pub unmatched_gt: Vec<usize>,
    /// Matched pairs whose types differ.
    pub type_errors: usize,
    /// Correct-type pairs / GT joints (unmatched GT joints count as wrong); `None` without GT joints.
    pub type_accuracy: Option<f64>,
    /// Axis Ang (°), mean over matched pairs.
    pub axis_ang: Option<f64>,
    /// Axis Pos (0.1 m), mean over matched pairs with a revolute GT joint.
    pub axis_pos: Option<f64>,
    /// Part Motion, mean over matched pairs (° for revolute GT joints, m for prismatic, as the peers mix them).
    pub part_motion: Option<f64>,
    /// Part Motion (°) over pairs with a revolute GT joint.
    pub part_motion_revolute: Option<f64>,
    /// Part Motion (m) over pairs with a prismatic GT joint.
    pub part_motion_prismatic: Option<f64>,
    /// CD-s: Chamfer distance of the static part (`None` when evaluated without meshes, or when the GT static
    /// part has no triangles, e.g. a door captured without its frame).
    pub cd_s: Option<ChamferDistance>,
    /// CD-m: Chamfer distance averaged over matched movable parts.
    pub cd_m: Option<ChamferDistance>,
    /// CD-m per matched movable part, in GT order.
    pub cd_m_parts: Vec<PartChamfer>,
    /// Matched predicted movable parts whose mesh has no triangles (a part the fit found no
    /// surface for): their joints are scored, but they have no CD-m.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unsurfaced_pred: Vec<usize>,
}

fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values
        .into_iter()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

fn mean_chamfer(parts: &[PartChamfer]) -> Option<ChamferDistance> {
    Some(ChamferDistance {
        cd_peer: mean(parts.iter().map(|p| p.chamfer.cd_peer))?,
        cd_mm: mean(parts.iter().map(|p| p.chamfer.cd_mm))?,
    })
}

fn chamfer_labelled(
    pred: &TriMesh,
    gt: &TriMesh,
    pred_name: &str,
    gt_name: &str,
    options: &ChamferOptions,
) -> Result<ChamferDistance, EvalError> {
    chamfer_meshes(pred, gt, options).map_err(|fault| match fault {
        MeshFault::First(reason) => EvalError::InvalidMesh {
            mesh: pred_name.into(),
            reason,
        },
        MeshFault::Second(reason) => EvalError::InvalidMesh {
            mesh: gt_name.into(),
            reason,
        },
        MeshFault::Distance(reason) => EvalError::InvalidMesh {
            mesh: format!("{pred_name} against {gt_name}"),
            reason,
        },
    })
}

/// Evaluates one object: matches joints ([`match_joints`]), averages their errors, and — with
/// `meshes = Some((predicted, ground_truth))` — computes CD-s on the static parts and CD-m on the movable parts
/// paired by the joint matching (predicted movable part `i` belongs to predicted joint `i`, likewise for GT).
/// Pass start-state meshes for the paper's protocol.
///
/// A predicted movable mesh with no triangles is left out of CD-m and named in
/// [`ObjectMetrics::unsurfaced_pred`].
///
/// Errors: invalid joints or meshes, or a movable mesh count different from the joint count on either side.
pub fn evaluate_object(
    id: &str,
    category: &str,
    pred_joints: &[GtJoint],
    gt_joints: &[GtJoint],
    meshes: Option<(&GtMeshes, &GtMeshes)>,
    options: &EvalOptions,
) -> Result<ObjectMetrics, EvalError> {
    let matching = match_joints(pred_joints, gt_joints)?;
    let pairs = &matching.pairs;
    let of_kind = |kind: JointKind| {
        mean(
            pairs
                .iter()
                .filter(|p| p.gt_kind == kind)
                .map(|p| p.part_motion),
        )
    };
    let (mut cd_s, mut cd_m_parts, mut unsurfaced_pred) = (None, Vec::new(), Vec::new());
    if let Some((pred_meshes, gt_meshes)) = meshes {
        for (side, m, joints) in [
            ("predicted", pred_meshes, pred_joints.len()),
            ("ground-truth", gt_meshes, gt_joints.len()),
        ] {
            if m.movable.len() != joints {
                return Err(EvalError::Inconsistent(format!(
                    "{side} object has {} movable part meshes but {joints} joints",
                    m.movable.len()
                )));
            }
        }
        // An object without a static surface (a door captured without its frame) has no CD-s.
        if !gt_meshes.static_part.triangles.is_empty() {
            cd_s = Some(chamfer_labelled(
                &pred_meshes.static_part,
                &gt_meshes.static_part,
                "predicted static part",
                "ground-truth static part",
                &options.chamfer,
            )?);
        }
        for p in pairs {
            if pred_meshes.movable[p.pred].triangles.is_empty() {
                unsurfaced_pred.push(p.pred);
                continue;
            }
            let chamfer = chamfer_labelled(
                &pred_meshes.movable[p.pred],
                &gt_meshes.movable[p.gt],
                &format!("predicted movable part {}", p.pred),
                &format!("ground-truth movable part {}", p.gt),
                &options.chamfer,
            )?;
            cd_m_parts.push(PartChamfer {
                pred: p.pred,
                gt: p.gt,
                chamfer,
            });
        }
    }
    let correct = pairs.iter().filter(|p| p.type_correct).count();
    Ok(ObjectMetrics {
        id: id.into(),
        category: category.into(),
        part_count: 1 + gt_joints.len(),
        predicted_joints: pred_joints.len(),
        type_accuracy: (!gt_joints.is_empty()).then(|| correct as f64 / gt_joints.len() as f64),
        axis_ang: mean(pairs.iter().map(|p| p.axis_ang)),
        axis_pos: mean(pairs.iter().filter_map(|p| p.axis_pos)),
        part_motion: mean(pairs.iter().map(|p| p.part_motion)),
        part_motion_revolute: of_kind(JointKind::Revolute),
        part_motion_prismatic: of_kind(JointKind::Prismatic),
        cd_s,
        cd_m: mean_chamfer(&cd_m_parts),
        cd_m_parts,
        unsurfaced_pred,
        joints: matching.pairs,
        unmatched_pred: matching.unmatched_pred,
        unmatched_gt: matching.unmatched_gt,
        type_errors: matching.type_errors,
    })
}

/// Scores `fit` against `dataset`'s ground truth (joints, and start-state meshes when both
/// sides have them) as object `id` of `category`; `None` without GT joints.
pub fn evaluate_fit(
    fit: &ObjectFit,
    dataset: &Dataset,
    id: &str,
    category: &str,
    options: &EvalOptions,
) -> Option<Result<ObjectMetrics, EvalError>> {
    let gt_joints = dataset.gt_joints.as_ref()?;
    let predicted = fit.as_ground_truth();
    let state = State::Start.index();
    let meshes = predicted.meshes[state]
        .as_ref()
        .zip(dataset.gt_meshes[state].as_ref());
    Some(evaluate_object(
        id,
        category,
        &fit.articulation.gt_joints(),
        gt_joints,
        meshes,
        options,
    ))
}
