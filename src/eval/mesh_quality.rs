//! Mesh quality of a reconstruction, per state and part: what makes a mesh simulation-ready
//! (one connected piece per part, few boundary edges, no non-manifold edges, no face spanning two
//! parts) and how close it is to the ground truth (Chamfer in both conventions of docs/design.md §7).

use serde::Serialize;

use super::chamfer::{ChamferDistance, ChamferOptions, chamfer_meshes};
use crate::data::{GtMeshes, TriMesh};
use crate::fit::reconstruct::{PhaseTimes, Reconstruction, RemeshStats, StateReconstruction};
use crate::fit::weld;
use crate::mesh::{edge_counts, face_components};

/// One part's mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartQuality {
    /// 0 = static base.
    pub part: usize,
    pub vertices: usize,
    pub faces: usize,
    /// Connected pieces (through shared vertices).
    pub components: usize,
    /// Connected pieces of the ground-truth part mesh after welding coincident vertices.
    pub gt_components: Option<usize>,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    /// Against the ground-truth part mesh, when there is one and both meshes have area.
    pub chamfer: Option<ChamferDistance>,
    /// Why there is no Chamfer distance, when there is none.
    pub chamfer_missing: Option<String>,
}

/// One state's meshes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StateQuality {
    pub state: crate::data::State,
    /// Faces of the final mesh whose vertices carry two part labels (0 after part-aware remeshing).
    pub cross_part_faces: usize,
    pub remesh: RemeshStats,
    pub initial_faces: usize,
    pub faces_split: usize,
    pub faces_pruned: usize,
    pub psnr_optimised: f64,
    pub psnr_remeshed: f64,
    pub psnr_recovered: f64,
    /// Mean PSNR over the state's held-out views (none without test views).
    pub psnr_test: Option<f64>,
    pub width: u32,
    pub height: u32,
    pub views: usize,
    pub times: PhaseTimes,
    pub parts: Vec<PartQuality>,
}

/// The report of a whole reconstruction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReconstructionReport {
    pub preset: crate::fit::preset::Preset,
    pub remesh: crate::fit::reconstruct::RemeshMode,
    pub num_parts: usize,
    pub states: Vec<StateQuality>,
}

/// Quality of one part mesh, against `gt` when given.
pub(crate) fn part_quality(
    part: usize,
    mesh: &TriMesh,
    gt: Option<&TriMesh>,
    options: &ChamferOptions,
) -> PartQuality {
    let edges = edge_counts(&mesh.triangles);
    let gt_components = gt.filter(|g| !g.triangles.is_empty()).map(|g| {
        let (_, faces, _) = weld(&g.positions, &g.triangles, 1e-5);
        face_components(&faces).1
    });
    let (chamfer, chamfer_missing) = match gt {
        None => (None, Some("no ground-truth mesh".to_string())),
        Some(g) => match chamfer_meshes(mesh, g, options) {
            Ok(c) => (Some(c), None),
            Err(e) => (None, Some(format!("{e:?}"))),
        },
    };
    PartQuality {
        part,
        vertices: mesh.positions.len(),
        faces: mesh.triangles.len(),
        components: face_components(&mesh.triangles).1,
        gt_components,
        boundary_edges: edges.boundary,
        non_manifold_edges: edges.non_manifold,
        chamfer,
        chamfer_missing,
    }
}

/// Quality of one state's reconstruction.
pub(crate) fn state_quality(
    state: &StateReconstruction,
    gt: Option<&GtMeshes>,
    options: &ChamferOptions,
) -> StateQuality {
    let gt_part = |k: usize| {
        gt.and_then(|g| {
            if k == 0 {
                Some(&g.static_part)
            } else {
                g.movable.get(k - 1)
            }
        })
    };
    StateQuality {
        state: state.state,
        cross_part_faces: crate::mesh::topology::cross_part_faces(&state.field.faces, &state.parts),
        remesh: state.remesh,
        initial_faces: state.initial_faces,
        faces_split: state.faces_split,
        faces_pruned: state.faces_pruned,
        psnr_optimised: state.psnr_optimised,
        psnr_remeshed: state.psnr_remeshed,
        psnr_recovered: state.psnr_recovered,
        psnr_test: state.psnr_test,
        width: state.width,
        height: state.height,
        views: state.views,
        times: state.times,
        parts: state
            .part_meshes
            .iter()
            .enumerate()
            .map(|(k, m)| part_quality(k, m, gt_part(k), options))
            .collect(),
    }
}

/// The report of `reconstruction`; `gt` holds the ground-truth part meshes per state (start,
/// end) when known, as [`crate::data::Dataset::gt_meshes`] does.
pub fn reconstruction_report(
    reconstruction: &Reconstruction,
    gt: &[Option<GtMeshes>; 2],
    options: &ChamferOptions,
) -> ReconstructionReport {
    ReconstructionReport {
        preset: reconstruction.config.preset,
        remesh: reconstruction.config.remesh,
        num_parts: reconstruction.num_parts,
        states: reconstruction
            .states
            .iter()
            .map(|s| state_quality(s, gt[s.state.index()].as_ref(), options))
            .collect(),
    }
}

/// What a part-aware reconstruction must satisfy, as a list of failures (empty = pass): no
/// cross-part face, every part a non-empty mesh with no more pieces than its ground truth (or
/// one), no non-manifold edge, a Chamfer distance below `max_cd_mm` to the ground truth, and a
/// recovered PSNR above `min_psnr`.
pub fn reconstruction_failures(
    report: &ReconstructionReport,
    max_cd_mm: f64,
    min_psnr: f64,
) -> Vec<String> {
    let mut failures = Vec::new();
    for s in &report.states {
        let state = s.state.name();
        if s.cross_part_faces != 0 {
            failures.push(format!("{state}: {} cross-part faces", s.cross_part_faces));
        }
        if s.psnr_recovered < min_psnr {
            failures.push(format!(
                "{state}: PSNR {:.2} dB < {min_psnr}",
                s.psnr_recovered
            ));
        }
        for p in &s.parts {
            let allowed = p.gt_components.unwrap_or(1).max(1);
            if p.faces == 0 || p.components > allowed {
                failures.push(format!(
                    "{state} part {}: {} faces in {} pieces (ground truth {allowed})",
                    p.part, p.faces, p.components
                ));
            }
            if p.non_manifold_edges > 0 {
                failures.push(format!(
                    "{state} part {}: {} non-manifold edges",
                    p.part, p.non_manifold_edges
                ));
            }
            match p.chamfer {
                Some(c) if c.cd_mm <= max_cd_mm => {}
                other => failures.push(format!(
                    "{state} part {}: Chamfer {other:?} (limit {max_cd_mm} mm)",
                    p.part
                )),
            }
        }
    }
    failures
}
