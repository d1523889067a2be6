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
    /// Distinct edges, and those used by one face / by three or more.
    pub edges: usize,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    /// Boundary edges of the welded ground-truth part mesh (0: a closed surface).
    pub gt_boundary_edges: Option<usize>,
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
    let (chamfer, chamfer_missing) = match gt {
        None => (None, Some("no ground-truth mesh".to_string())),
        Some(g) => match chamfer_meshes(mesh, g, options) {
            Ok(c) => (Some(c), None),
            Err(e) => (None, Some(format!("{e:?}"))),
        },
    };
    PartQuality {
        chamfer,
        chamfer_missing,
        ..part_topology(part, mesh, gt)
    }
}

/// The topology half of [`part_quality`] (no Chamfer distance: cheap).
fn part_topology(part: usize, mesh: &TriMesh, gt: Option<&TriMesh>) -> PartQuality {
    let edges = edge_counts(&mesh.triangles);
    let gt_topology = gt.and_then(gt_topology);
    PartQuality {
        part,
        vertices: mesh.positions.len(),
        faces: mesh.triangles.len(),
        components: face_components(&mesh.triangles).1,
        gt_components: gt_topology.map(|(pieces, _)| pieces),
        edges: edges.edges,
        boundary_edges: edges.boundary,
        non_manifold_edges: edges.non_manifold,
        gt_boundary_edges: gt_topology.map(|(_, boundary)| boundary),
        chamfer: None,
        chamfer_missing: None,
    }
}

/// Connected pieces and boundary edges of a ground-truth mesh, its coincident vertices welded;
/// `None` for an empty one.
fn gt_topology(gt: &TriMesh) -> Option<(usize, usize)> {
    if gt.triangles.is_empty() {
        return None;
    }
    let (_, faces, _) = weld(&gt.positions, &gt.triangles, 1e-5);
    Some((face_components(&faces).1, edge_counts(&faces).boundary))
}

/// The ground-truth mesh of part `k` (0 = static base) in `gt`.
fn gt_part(gt: Option<&GtMeshes>, k: usize) -> Option<&TriMesh> {
    gt.and_then(|g| {
        if k == 0 {
            Some(&g.static_part)
        } else {
            g.movable.get(k - 1)
        }
    })
}

/// Quality of one state's reconstruction.
pub(crate) fn state_quality(
    state: &StateReconstruction,
    gt: Option<&GtMeshes>,
    options: &ChamferOptions,
) -> StateQuality {
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
            .map(|(k, m)| part_quality(k, m, gt_part(gt, k), options))
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

/// The mesh facts of a reconstruction summed over both states' parts: what issue 27 asks of a
/// simulation-ready twin.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct MeshSummary {
    /// Part meshes (both states).
    pub parts: usize,
    pub edges: usize,
    pub boundary_edges: usize,
    /// The same over the parts whose ground truth is a closed surface.
    pub closed_parts: usize,
    pub closed_part_edges: usize,
    pub closed_part_boundary_edges: usize,
    pub non_manifold_edges: usize,
    pub cross_part_faces: usize,
    /// Parts in more connected pieces than their ground truth.
    pub split_parts: usize,
    /// Short holes closed after remeshing.
    pub holes_closed: usize,
    /// Fill faces left out because the views saw through them.
    pub fill_faces_refused: usize,
}

impl MeshSummary {
    /// Boundary edges as a fraction of all edges of the parts whose ground truth is closed.
    pub fn closed_boundary_fraction(&self) -> f64 {
        self.closed_part_boundary_edges as f64 / self.closed_part_edges.max(1) as f64
    }

    /// Counts part `p` in.
    fn add_part(&mut self, p: &PartQuality) {
        let closed = p.gt_boundary_edges == Some(0);
        self.parts += 1;
        self.edges += p.edges;
        self.boundary_edges += p.boundary_edges;
        self.closed_parts += closed as usize;
        self.closed_part_edges += if closed { p.edges } else { 0 };
        self.closed_part_boundary_edges += if closed { p.boundary_edges } else { 0 };
        self.non_manifold_edges += p.non_manifold_edges;
        self.split_parts += p.gt_components.is_some_and(|g| p.components > g) as usize;
    }

    /// The sum of `self` and `other`.
    pub fn plus(&self, other: &MeshSummary) -> MeshSummary {
        MeshSummary {
            parts: self.parts + other.parts,
            edges: self.edges + other.edges,
            boundary_edges: self.boundary_edges + other.boundary_edges,
            closed_parts: self.closed_parts + other.closed_parts,
            closed_part_edges: self.closed_part_edges + other.closed_part_edges,
            closed_part_boundary_edges: self.closed_part_boundary_edges
                + other.closed_part_boundary_edges,
            non_manifold_edges: self.non_manifold_edges + other.non_manifold_edges,
            cross_part_faces: self.cross_part_faces + other.cross_part_faces,
            split_parts: self.split_parts + other.split_parts,
            holes_closed: self.holes_closed + other.holes_closed,
            fill_faces_refused: self.fill_faces_refused + other.fill_faces_refused,
        }
    }
}

/// [`MeshSummary`] of `reconstruction` against the ground-truth part meshes per state (start,
/// end) when known (no Chamfer distances: cheap enough for every benchmark object).
pub fn mesh_summary(reconstruction: &Reconstruction, gt: &[Option<GtMeshes>; 2]) -> MeshSummary {
    let mut sum = MeshSummary::default();
    for s in &reconstruction.states {
        sum.cross_part_faces += crate::mesh::topology::cross_part_faces(&s.field.faces, &s.parts);
        sum.holes_closed += s.remesh.holes.closed;
        sum.fill_faces_refused += s.remesh.holes.refused_faces;
        for (k, mesh) in s.part_meshes.iter().enumerate() {
            sum.add_part(&part_topology(
                k,
                mesh,
                gt_part(gt[s.state.index()].as_ref(), k),
            ));
        }
    }
    sum
}
