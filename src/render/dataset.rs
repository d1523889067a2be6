//! Two-state datasets from an articulated object: the Articulate-100 recipe.
//!
//! [`render_dataset`] draws a start state from `[0.6, 0.8]` and an end state from `[0.2, 0.4]` of every part's
//! joint range (normalised to [0, 1]), samples cameras on the upper hemisphere (or the whole sphere) around the
//! object, renders RGBA, depth and part maps for the train and test views of both states, and writes the
//! dataset layout of `data` with `gt/trans.json` and per-part GT meshes of both states. Frames are encoded and
//! handed to a sink as they are rendered, so memory stays at one frame whatever the view count.
//!
//! Ground truth (docs/design.md §2): one joint per movable part in part order, axis point `o` and direction `d` in
//! world coordinates, `l` / `r` the joint values at start / end (degrees for revolute and continuous joints,
//! metres for prismatic ones). Objects the part model cannot describe are refused with a clear
//! [`ObjectProblem`]: nothing moves, a movable part hanging on another movable part, a movable part without
//! surface, an object smaller than [`MIN_OBJECT_SIZE`] or larger than [`MAX_OBJECT_SIZE`], a joint whose range is empty. A static base without
//! surface is allowed (a door without its frame); its GT mesh is then empty and evaluation reports no CD-s.

use glam::{Affine3A, Vec3};

use super::{GtRenderer, PartMesh, RenderedView, posed_part_meshes, sample_state, sample_views};
use crate::data::sensor::{self, SensorModel};
use crate::data::{
    Camera, DataError, DatasetWriter, FileSet, Frame, GtJoint, GtMeshes, JointKind as GtKind,
    Split, State, TriMesh, WriteOptions,
};
use crate::gpu::{GpuContext, GpuError};
use crate::object::sampling::area_cdf;
use crate::object::{ArticulatedObject, JointKind, mesh_bounds};
use crate::rng::Rng;

/// Objects whose bounding box diagonal is below this (metres) are refused as having no volume to image.
pub const MIN_OBJECT_SIZE: f32 = 1e-3;

/// Largest bounding-box diagonal of an object in metres: framed by the cameras, a larger one puts
/// depths past the 65.535 m a millimetre depth PNG holds.
pub const MAX_OBJECT_SIZE: f32 = 25.0;

/// How to render a dataset. [`Default`] is the paper's Articulate-100 setting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSpec {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Train views per state.
    pub train_views: usize,
    /// Test views per state (0 writes no test split).
    pub test_views: usize,
    /// Horizontal field of view, radians.
    pub fov_x: f32,
    /// Normalised joint-range interval the start state is drawn from.
    pub start_range: (f32, f32),
    /// Normalised joint-range interval the end state is drawn from.
    pub end_range: (f32, f32),
    /// Cameras on the upper hemisphere (above the object's centre) instead of the whole sphere.
    pub upper_hemisphere: bool,
    /// Seed of the state draw and the camera positions (and of the sensor's degradation).
    pub seed: u64,
    /// Which camera the written frames look as if they came from (default: exact renders).
    pub sensor: SensorModel,
}

impl Default for RenderSpec {
    fn default() -> Self {
        RenderSpec {
            width: 800,
            height: 800,
            train_views: 100,
            test_views: 20,
            // Blender's default 50 mm lens on a 36 mm sensor, as in the NeRF-synthetic family of datasets.
            fov_x: 0.691_111,
            start_range: (0.6, 0.8),
            end_range: (0.2, 0.4),
            upper_hemisphere: true,
            seed: 0,
            sensor: SensorModel::Ideal,
        }
    }
}

/// Why an object cannot become a dataset.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObjectProblem {
    /// No movable joint survives the part view.
    #[error("object '{0}' has no movable joint: there is no articulation to capture")]
    NothingMoves(String),
    /// A movable part hangs on another movable part.
    #[error(
        "joint '{joint}' moves part {part}, which hangs on movable part {parent}: ArtMesh datasets need every \
         movable part to move relative to the static base (fix the other joint or make one of them fixed)"
    )]
    NestedPart {
        /// The joint of the nested part.
        joint: String,
        /// The nested part.
        part: usize,
        /// The movable part it hangs on.
        parent: usize,
    },
    /// A movable part with no triangle of positive area.
    #[error(
        "part {part} (links {links}) has no triangle of positive area: give its links visual geometry that is not empty or flat"
    )]
    NoSurface {
        /// The part.
        part: usize,
        /// Its link names, comma-separated.
        links: String,
    },
    /// The object is (nearly) a point.
    #[error(
        "object '{name}' has zero volume: its bounding box is {size:?} m (needs a diagonal of at least {min} m)"
    )]
    ZeroVolume {
        /// Object name.
        name: String,
        /// Bounding-box size.
        size: [f32; 3],
        /// [`MIN_OBJECT_SIZE`].
        min: f32,
    },
    /// The object is too large (or has a non-finite vertex) for the depth maps to hold it.
    #[error(
        "object '{name}' spans {size:?} m across both states: a capture needs a bounding-box diagonal of at most {max} m (depth PNGs hold up to 65.535 m); check the mesh's units and <mesh scale>"
    )]
    TooLarge {
        /// Object name.
        name: String,
        /// Bounding-box size.
        size: [f32; 3],
        /// [`MAX_OBJECT_SIZE`].
        max: f32,
    },
    /// A joint whose lower and upper limits coincide: both states would be the same.
    #[error(
        "joint '{joint}' has an empty range [{lower}, {upper}]: start and end states would be identical"
    )]
    EmptyRange {
        /// Joint name.
        joint: String,
        /// Lower limit.
        lower: f32,
        /// Upper limit.
        upper: f32,
    },
    /// A bad render specification.
    #[error("{0}")]
    BadSpec(String),
}

/// Everything that can stop [`render_dataset`].
#[derive(Debug, thiserror::Error)]
pub enum DatasetRenderError {
    /// The object cannot be captured as a two-state dataset.
    #[error(transparent)]
    Object(#[from] ObjectProblem),
    /// The GPU failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// Encoding or the sink failed.
    #[error(transparent)]
    Data(#[from] DataError),
}

/// Everything that can stop [`capture_dataset`]: the render, or reading its files back.
#[derive(Debug, thiserror::Error)]
pub enum CaptureError {
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] DatasetRenderError),
    /// The rendered files do not read back as a valid dataset.
    #[error(transparent)]
    ReadBack(#[from] crate::data::DatasetErrors),
}

/// Ground truth of a two-state capture.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureTruth {
    /// Joint values (one per joint of the object) at start and end.
    pub states: [Vec<f32>; 2],
    /// One joint per movable part, in part order, in `trans.json` units.
    pub joints: Vec<GtJoint>,
    /// Part meshes (world frame) at start and end.
    pub meshes: [GtMeshes; 2],
}

/// Checks that `obj` fits the part model (see the module docs) and returns its ground truth at `states`.
pub fn capture_truth(
    obj: &ArticulatedObject,
    states: [Vec<f32>; 2],
) -> Result<CaptureTruth, ObjectProblem> {
    let posed = states.each_ref().map(|q| posed_part_meshes(obj, q));
    truth_of_posed(obj, states, &posed).map(|(truth, _)| truth)
}

/// [`capture_truth`] for meshes already posed at `states` (the renderer needs them too), with
/// the posed meshes' bounding box over both states (the renderer frames it).
fn truth_of_posed(
    obj: &ArticulatedObject,
    states: [Vec<f32>; 2],
    posed: &[Vec<PartMesh>; 2],
) -> Result<(CaptureTruth, (Vec3, Vec3)), ObjectProblem> {
    let parts = obj.parts();
    if parts.movable_count() == 0 {
        return Err(ObjectProblem::NothingMoves(obj.name.clone()));
    }
    // The size before the surfaces: an overflowing one also makes their areas non-finite.
    let (lo, hi) =
        mesh_bounds(posed.iter().flatten().map(|m| &m.mesh)).unwrap_or((Vec3::ZERO, Vec3::ZERO));
    // A vertex that is not finite once posed (3e38, moved) counts as an infinite size: the
    // bounds leave it out, and the cameras would be NaN.
    let finite = posed
        .iter()
        .flatten()
        .all(|m| m.mesh.positions.iter().all(|p| p.is_finite()));
    let size = if finite { hi - lo } else { Vec3::INFINITY };
    let diagonal = size.length();
    if diagonal > MAX_OBJECT_SIZE {
        return Err(ObjectProblem::TooLarge {
            name: obj.name.clone(),
            size: size.to_array(),
            max: MAX_OBJECT_SIZE,
        });
    }
    if diagonal < MIN_OBJECT_SIZE {
        return Err(ObjectProblem::ZeroVolume {
            name: obj.name.clone(),
            size: size.to_array(),
            min: MIN_OBJECT_SIZE,
        });
    }
    let start_poses = obj.forward_kinematics(&states[0]);
    let mut joints = Vec::with_capacity(parts.movable_count());
    for (k, part) in parts.parts.iter().enumerate().skip(1) {
        let Some(j) = part.joint else { continue };
        let joint = &obj.joints[j];
        let parent = parts.link_part.get(joint.parent).copied().unwrap_or(0);
        if parent != 0 {
            return Err(ObjectProblem::NestedPart {
                joint: joint.name.clone(),
                part: k,
                parent,
            });
        }
        let (lower, upper) = joint.range().unwrap_or((0.0, 0.0));
        let opens = upper > lower; // false for NaN limits too
        if !opens {
            return Err(ObjectProblem::EmptyRange {
                joint: joint.name.clone(),
                lower,
                upper,
            });
        }
        // The base does not move, so the joint frame is the same at both states.
        let frame: Affine3A = start_poses[joint.parent] * joint.origin;
        let value = |s: usize| states[s].get(j).copied().unwrap_or(0.0);
        let (kind, scale) = match joint.kind {
            JointKind::Prismatic => (GtKind::Prismatic, 1.0),
            _ => (GtKind::Revolute, 180.0 / std::f32::consts::PI),
        };
        joints.push(GtJoint {
            kind,
            origin: frame.translation.into(),
            direction: (frame.matrix3 * joint.axis).normalize_or_zero(),
            start: value(0) * scale,
            end: value(1) * scale,
        });
    }
    let meshes = posed.each_ref().map(|p| part_meshes(p, parts.parts.len()));
    // The base may be empty (a door without its frame: there is nothing static to see); every movable part
    // needs a surface, or it could be neither seen nor scored.
    for (k, mesh) in meshes[0].iter().enumerate().skip(1) {
        // The check the Chamfer sampling applies: what passes here can be scored.
        if area_cdf(mesh).is_err() {
            let links: Vec<&str> = parts.parts[k]
                .links
                .iter()
                .map(|&l| obj.links[l].name.as_str())
                .collect();
            return Err(ObjectProblem::NoSurface {
                part: k,
                links: links.join(", "),
            });
        }
    }
    let [start, end] = meshes.map(|mut m| {
        let static_part = m.remove(0);
        GtMeshes {
            static_part,
            movable: m,
        }
    });
    let truth = CaptureTruth {
        states,
        joints,
        meshes: [start, end],
    };
    Ok((truth, (lo, hi)))
}

/// One merged triangle mesh per part.
fn part_meshes(posed: &[PartMesh], count: usize) -> Vec<TriMesh> {
    let mut out = vec![TriMesh::default(); count];
    for m in posed {
        let Some(target) = usize::try_from(m.part).ok().and_then(|k| out.get_mut(k)) else {
            continue;
        };
        let base = target.positions.len() as u32;
        target.positions.extend_from_slice(&m.mesh.positions);
        target
            .triangles
            .extend(m.mesh.indices.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

/// What [`render_dataset`] produced.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedDataset {
    /// Parts including the base.
    pub num_parts: usize,
    /// Ground truth of the capture.
    pub truth: CaptureTruth,
    /// Frames rendered (all states and splits).
    pub frames: usize,
}

/// Progress of [`render_dataset`]: frames done out of the total.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderProgress {
    /// Frames rendered so far.
    pub done: usize,
    /// Frames to render.
    pub total: usize,
}

/// Renders the two-state dataset of `obj` in memory and reads it back as a [`Dataset`] (what a
/// user would drop in), for tests and the demos; `progress` hears about every frame.
pub async fn capture_dataset(
    ctx: &GpuContext,
    obj: &ArticulatedObject,
    spec: &RenderSpec,
    progress: &mut dyn FnMut(RenderProgress),
) -> Result<crate::data::Dataset, CaptureError> {
    let mut files = FileSet::new();
    render_dataset(
        ctx,
        obj,
        spec,
        &mut |batch| {
            files.extend(batch);
            Ok(())
        },
        progress,
    )
    .await?;
    Ok(crate::data::Dataset::from_files(&files)?)
}

/// Renders the two-state dataset of `obj` (see the module docs). Every batch of files — one frame's images,
/// then the transforms files and ground truth — goes to `sink` as soon as it is ready; `progress` hears about
/// every frame.
pub async fn render_dataset(
    ctx: &GpuContext,
    obj: &ArticulatedObject,
    spec: &RenderSpec,
    sink: &mut dyn FnMut(FileSet) -> Result<(), DataError>,
    progress: &mut dyn FnMut(RenderProgress),
) -> Result<RenderedDataset, DatasetRenderError> {
    check_spec(spec)?;
    let mut rng = Rng::new(spec.seed);
    let states = [
        sample_state(obj, spec.start_range, &mut rng),
        sample_state(obj, spec.end_range, &mut rng),
    ];
    let posed = states.each_ref().map(|q| posed_part_meshes(obj, q));
    // Framed on both states at once.
    let (truth, (lo, hi)) = truth_of_posed(obj, states, &posed)?;
    let size = hi - lo;
    let renderer = GtRenderer::new(ctx, spec.width, spec.height)?;
    let template = Camera::from_fov(
        glam::Mat4::IDENTITY,
        spec.width,
        spec.height,
        spec.fov_x,
        None,
    );
    let half_fov = 0.5 * template.intrinsics.fov_x().min(template.intrinsics.fov_y());
    let centre = (lo + hi) * 0.5;
    // Far enough that the bounding sphere of both states fits every view, with a 10 % margin.
    let distance = 0.5 * size.length() / half_fov.sin() * 1.1;
    let mut writer = DatasetWriter::new(WriteOptions::default());
    let total = 2 * (spec.train_views + spec.test_views);
    let mut done = 0;
    for state in State::ALL {
        for (split, count) in [
            (Split::Train, spec.train_views),
            (Split::Test, spec.test_views),
        ] {
            let seed = rng.next_u64();
            let poses = sample_views(count, centre, distance, seed, spec.upper_hemisphere);
            for (i, pose) in poses.into_iter().enumerate() {
                let camera = Camera {
                    camera_to_world: pose,
                    intrinsics: template.intrinsics,
                };
                let view = renderer
                    .render_view(ctx, &posed[state.index()], &camera)
                    .await?;
                let mut frame = frame_of(view, format!("{i:04}"), camera, state.default_time());
                let seed = sensor::frame_seed(spec.seed, state, split, i);
                spec.sensor.degrade(&mut frame, seed);
                sink(writer.add_frame(state, split, &frame)?)?;
                done += 1;
                progress(RenderProgress { done, total });
            }
        }
    }
    let [start, end] = truth.meshes.clone();
    let num_parts = 1 + truth.joints.len();
    sink(writer.finish(num_parts, Some(&truth.joints), &[Some(start), Some(end)])?)?;
    Ok(RenderedDataset {
        num_parts,
        truth,
        frames: total,
    })
}

fn frame_of(view: RenderedView, name: String, camera: Camera, time: f32) -> Frame {
    Frame {
        name,
        camera,
        time,
        rgba: view.rgba,
        depth: Some(view.depth),
        parts: Some(view.parts),
    }
}

fn check_spec(spec: &RenderSpec) -> Result<(), ObjectProblem> {
    let bad = |m: String| Err(ObjectProblem::BadSpec(m));
    if spec.train_views == 0 {
        return bad("at least one train view per state is needed".into());
    }
    if !(spec.fov_x > 0.0 && spec.fov_x < std::f32::consts::PI) {
        return bad(format!(
            "field of view {} rad is outside (0, π)",
            spec.fov_x
        ));
    }
    for (name, (a, b)) in [("start", spec.start_range), ("end", spec.end_range)] {
        if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) || a > b {
            return bad(format!(
                "{name} state range [{a}, {b}] must be an interval inside [0, 1] (fractions of each joint's range)"
            ));
        }
    }
    Ok(())
}
