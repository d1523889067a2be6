//! What the reconstruction of a state produces: the final field and part meshes, what the
//! densification and remeshing did, the PSNR after each stage and the time each took.

use crate::articulation::observed::{CloudOptions, ObservedState};
use serde::Serialize;

use super::config::{ReconstructionConfig, RemeshMode};
use crate::data::{GroundTruth, GtMeshes, State, TriMesh};
use crate::fit::photometric::CurvePoint;
use crate::raster::MeshField;

/// Wall-clock seconds spent in each phase of one state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PhaseTimes {
    pub initialise_s: f64,
    /// The optimisation steps (GPU), without the densify/prune edits.
    pub optimise_s: f64,
    /// Densify/prune: face statistics read back, CPU edits, re-upload, Adam remap.
    pub densify_s: f64,
    pub remesh_s: f64,
    pub recover_s: f64,
    /// PSNR measurements over all views between stages.
    pub measure_s: f64,
    pub total_s: f64,
}

impl PhaseTimes {
    /// Adds `other`'s seconds to these.
    pub fn accumulate(&mut self, other: &PhaseTimes) {
        for (mine, theirs) in self.phases_mut().into_iter().zip(other.phases()) {
            *mine += theirs.1;
        }
        self.total_s += other.total_s;
    }

    /// (phase, seconds) without the total.
    pub fn phases(&self) -> [(&'static str, f64); 6] {
        [
            ("initialise", self.initialise_s),
            ("optimise", self.optimise_s),
            ("densify", self.densify_s),
            ("remesh", self.remesh_s),
            ("recover", self.recover_s),
            ("measure", self.measure_s),
        ]
    }

    /// The same fields as [`PhaseTimes::phases`], in the same order, to add to.
    fn phases_mut(&mut self) -> [&mut f64; 6] {
        [
            &mut self.initialise_s,
            &mut self.optimise_s,
            &mut self.densify_s,
            &mut self.remesh_s,
            &mut self.recover_s,
            &mut self.measure_s,
        ]
    }

    /// The phase with the largest share of the total, and that share.
    pub fn dominant(&self) -> (&'static str, f64) {
        let (name, t) = self
            .phases()
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or(("none", 0.0));
        (name, t / self.total_s.max(1e-9))
    }
}

/// What the remeshing step did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct RemeshStats {
    pub mode: Option<RemeshMode>,
    /// Faces before remeshing and how many of them spanned two hardened parts (all are dropped).
    pub faces_before: usize,
    pub cross_part_faces_before: usize,
    /// Faces the restricted Delaunay step built.
    pub faces_built: usize,
    /// Of those, spanning two parts: 0 for part-aware remeshing by construction; for the
    /// global ablation, the faces that would tear or stretch under the parts' rigid motions.
    pub cross_part_faces: usize,
    /// Faces in small floating pieces that were dropped.
    pub floater_faces: usize,
    /// Vertices dropped: thinned out before remeshing, or used by no rebuilt face.
    pub unused_vertices: usize,
    /// Boundary loops of the rebuilt parts and those closed (`close_holes`).
    pub holes: crate::mesh::HoleStats,
    /// Rim runs zipped to their other side (`rim_gap`), and the faces that took.
    pub rims: crate::mesh::RimStats,
}

/// One state's reconstruction.
#[derive(Debug, Clone)]
pub struct StateReconstruction {
    pub state: State,
    /// The final field: remeshed, recovered, part logits hardened.
    pub field: MeshField,
    /// Hardened part per vertex.
    pub parts: Vec<u32>,
    /// One mesh per part (static base first).
    pub part_meshes: Vec<TriMesh>,
    pub remesh: RemeshStats,
    /// Faces split and pruned over all densification steps.
    pub faces_split: usize,
    pub faces_pruned: usize,
    pub initial_faces: usize,
    /// Mean training PSNR after the optimisation, after remeshing, after recovery.
    pub psnr_optimised: f64,
    pub psnr_remeshed: f64,
    pub psnr_recovered: f64,
    /// Mean PSNR of the final mesh over the state's held-out (test) views at the working size,
    /// rendered as in training; `None` when the dataset has no test views of the state.
    pub psnr_test: Option<f64>,
    pub curve: Vec<CurvePoint>,
    pub times: PhaseTimes,
    /// Size and number of the training views used.
    pub width: u32,
    pub height: u32,
    pub views: usize,
}

/// Both states' reconstructions.
#[derive(Debug, Clone)]
pub struct Reconstruction {
    pub config: ReconstructionConfig,
    pub num_parts: usize,
    pub states: Vec<StateReconstruction>,
    /// Both states' measured part surfaces from the training views, when the surfaces were
    /// measured, with the options they were sampled with (the articulation's measured joints
    /// reuse them rather than sample them again).
    pub train_clouds: Option<(CloudOptions, [ObservedState; 2])>,
}

impl Reconstruction {
    /// The part meshes in the layout of a dataset's `gt/` folder (`gt/{state}/{state}_static_rotate.ply`,
    /// `..._dynamic_{i}_rotate.ply`), so `artmesh eval` and the peers' scripts read them as predictions.
    pub fn as_ground_truth(&self) -> GroundTruth {
        let mut meshes: [Option<GtMeshes>; 2] = [None, None];
        for s in &self.states {
            let mut parts = s.part_meshes.iter().cloned();
            meshes[s.state.index()] = Some(GtMeshes {
                static_part: parts.next().unwrap_or_default(),
                movable: parts.collect(),
            });
        }
        GroundTruth {
            joints: None,
            meshes,
        }
    }
}
