//! The articulation phase (paper §3.2 and appendix "Training Details"): the two reconstructed
//! states' meshes are frozen and only the [`ArticulationField`] — one rigid motion per movable
//! part — is optimised.
//!
//! Schedule over `iterations` steps:
//! 1. **Candidates** (until `decide_at`): a revolute and a prismatic candidate per part, both
//!    seeded by [`initial_candidates`], trained on alternating steps by the forward pixel-wise
//!    motion consistency (state t₁'s mesh moved by g⁺, rendered from a state-t₂ camera).
//! 2. **Bake-off** at `decide_at`: per part, the loss masked to the part's pixels in state t₂ with
//!    only that part moved by each candidate, averaged over all state-t₂ views; the lower wins
//!    (ties to revolute, as in the paper). The winner's Adam moments start from zero.
//! 3. **Refine**: the winners with type-masked gradients, the backward pixel-wise term (state
//!    t₂'s mesh moved by the analytic inverse g⁻, rendered from state-t₁ cameras) from
//!    `backward_from`, and the vertex-wise term in both directions. Each step's pixel-wise
//!    gradients come from one view per direction (the paper) or from all of them
//!    ([`RefineViews`]).
//!
//! 4. **Axis registration** (ours, [`register_along_axis`]; `tiny` and `fast`): per joint, the
//!    angle or travel alone, axis and pivot held, by trimmed point-to-plane ICP between the
//!    part's two surfaces.
//!
//! The pixel-wise gradients come back as per-part [`PartSums`] from the GPU
//! ([`MovedMesh::read_sums`]), the vertex-wise ones from the CPU; [`PartMotion::gradient`] turns
//! both into parameter gradients.

use glam::{DMat3, DVec3, Vec3};
use serde::Serialize;

use super::observer::{Observer, checkpoint};
use super::photometric::encode_loss_and_backward;
use super::reconstruct::{Phase, Preset, Progress, Reconstruction, training_views};
use super::views::ViewCycle;
use crate::articulation::axis_registration::{AxisRegistration, register_along_axis};
use crate::articulation::geometric::{Anchor, CloudPair, GeometricJoint, SMALL_MARGIN, fit_joint};
use crate::articulation::init::{JointCandidates, initial_candidates, principal_frame};
use crate::articulation::kernels::{MotionKernels, MovedMesh};
use crate::articulation::observed::{CloudOptions, ObservedState, observe_dataset};
use crate::articulation::vertex_motion::{StateSurface, VertexMotionWeights, vertex_motion_loss};
use crate::articulation::{MotionAdam, MotionMask, MotionRates, PartMotion, PartSums};
use crate::data::{Dataset, Frame, GtJoint, JointKind, Split, State};
use crate::gpu::{GpuContext, GpuError, GpuResult, now_seconds};
use crate::loss::{ImageLoss, LossWeights, SSIM_C1, SSIM_C2, TargetImages, TargetView, ssim_taps};
use crate::raster::{GpuField, MeshField, RasterSettings, RasterState, Rasterizer};
use crate::rng::Rng;

/// Which parts of the motion-consistency objective are on (the paper's Table 4 ablations; the
/// fourth, part-aware remeshing, is [`super::reconstruct::RemeshMode`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Ablation {
    /// The vertex-wise colour term.
    pub vertex_color: bool,
    /// The vertex-wise opacity term.
    pub vertex_opacity: bool,
    /// The backward direction (backward pixel-wise and vertex-wise terms).
    pub backward: bool,
}

impl Ablation {
    /// The full model.
    pub const FULL: Ablation = Ablation {
        vertex_color: true,
        vertex_opacity: true,
        backward: true,
    };

    /// The ablation named as on the command line (`full`, `no-vertex-color`, `no-vertex-opacity`,
    /// `no-backward`).
    pub fn parse(name: &str) -> Result<Ablation, String> {
        let full = Ablation::FULL;
        Ok(match name {
            "full" => full,
            "no-vertex-color" => Ablation {
                vertex_color: false,
                ..full
            },
            "no-vertex-opacity" => Ablation {
                vertex_opacity: false,
                ..full
            },
            "no-backward" => Ablation {
                backward: false,
                ..full
            },
            other => {
                return Err(format!(
                    "unknown ablation {other:?}: expected full, no-vertex-color, no-vertex-opacity or no-backward"
                ));
            }
        })
    }
}

/// How many views one refinement step's pixel-wise gradients average, per direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RefineViews {
    /// The next view of a shuffled cycle: the paper's stochastic steps.
    One,
    /// Every view: the full-batch gradient, as many renders per step as the state has views.
    All,
}

/// How the articulation uses the part surfaces measured by the dataset's full-resolution depth
/// and part maps ([`crate::articulation::geometric`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GeometryUse {
    /// Not at all: the paper's method (seeds from the reconstructed meshes, photometric stages).
    Off,
    /// Measured joints seed the photometric stages of every part, the measured type evidence
    /// overrules a bake-off it contradicts by a clear margin, and the result is kept only where it
    /// fits the measured surfaces at least as well as its seed.
    Seed,
    /// As `Seed`, but a joint the measurements settle (motion visible, type by a clear margin)
    /// is taken as measured: the photometric stages run only for the parts they cannot settle
    /// (no depth, unobservable motion, a close type call), and not at all when none is left.
    Settle,
}

impl GeometryUse {
    /// The mode named as on the command line (`off`, `seed`, `settle`).
    pub fn parse(name: &str) -> Result<GeometryUse, String> {
        match name {
            "off" => Ok(GeometryUse::Off),
            "seed" => Ok(GeometryUse::Seed),
            "settle" => Ok(GeometryUse::Settle),
            other => Err(format!(
                "unknown geometry mode {other:?}: expected off, seed or settle"
            )),
        }
    }
}

/// Schedule, weights and learning rates of the articulation phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArticulationConfig {
    pub iterations: u32,
    /// Fraction of the phase at which the joint type is decided and the vertex-wise term starts.
    pub decide_at: f32,
    /// Fraction at which the backward pixel-wise term starts (the paper delays it).
    pub backward_from: f32,
    /// λ_PMC and λ_VMC (paper: 0.05 each).
    pub pixel_weight: f64,
    pub vertex_weight: f64,
    /// The pixel-wise term's image loss.
    pub weights: LossWeights,
    /// Window sharpness γ and opacity floor of the articulation renders. Softer than the
    /// reconstruction's final opaque, hard triangles: through those, moving a part changes which
    /// pixels it covers only in jumps the gradient cannot see (φ = u^γ saturates the opacity
    /// clamp), and the remaining colour-interpolation gradient drifts the motion away.
    pub gamma: f32,
    pub opacity_floor: f32,
    pub vertex: VertexMotionWeights,
    pub rates: MotionRates,
    /// Views per refinement step. At 32–64 px the objective has local minima a degree or more
    /// apart, and with single-view steps their noise picks which one a fit ends in.
    pub refine_views: RefineViews,
    /// Each stage (candidates, refine) decays the rates log-linearly to this fraction of
    /// themselves (1 = the paper's constant rates). Ours: with a few hundred single-view steps
    /// instead of 20 000, constant rates leave Adam's per-step jitter (≈ one rate per step) in
    /// the result; measured on the quick suite's laptop and cabinet (fast preset), 0.05 took the
    /// cabinet's Axis Ang from 18.1° (seeds) to 6.2° where constant rates drifted away.
    pub final_rate: f64,
    /// Whether the refined joints' magnitudes are registered along their axes
    /// ([`register_along_axis`]). On the fast laptop it took the motion 0.51° → 0.15° from the
    /// truth and the browser-vs-native gap 0.84° → 0.28° (README "Browser app").
    pub register_magnitude: bool,
    /// How the measured part surfaces are used.
    pub geometry: GeometryUse,
    /// How those surfaces are sampled.
    pub clouds: CloudOptions,
    /// The refinement stops early once its reported objective changes by less than this fraction
    /// between two reports (0: never).
    pub flat_tolerance: f64,
    pub ablation: Ablation,
    /// Loss terms are read back (and reported) every this many steps.
    pub report_every: u32,
    pub seed: u64,
}

impl ArticulationConfig {
    /// Renders per refinement step, both directions, for states of `views` training views.
    pub fn refine_renders(&self, views: usize) -> usize {
        match self.refine_views {
            RefineViews::One => 2,
            RefineViews::All => 2 * views.max(1),
        }
    }

    /// The step at which the joint types are decided: candidates before it, refinement after.
    pub fn decision_step(&self) -> u32 {
        ((self.iterations as f32 * self.decide_at) as u32).min(self.iterations)
    }

    /// The articulation settings of a preset (tiny 40, fast 300, paper 20 000 steps).
    ///
    /// `tiny` and `fast` train at a quarter of the paper's rates and refine on every view: with
    /// one view per step and the paper's rates, changes that should not matter (the SSIM weight
    /// × (1 + 1e-6), SwiftShader's rounding instead of lavapipe's) moved the fast laptop's axis
    /// by up to 1.4° and its motion by 2.3°; now by 0.13° and 0.26° (`bench spread`, README
    /// "Browser app"), at about three times the fit's time. Keeping the paper's rates for the
    /// candidates brought that back to 2.1°. `paper` keeps the paper's 20 000 single-view steps
    /// at full rates (every one of 100 views per step would cost 100×).
    pub fn preset(preset: Preset) -> Self {
        let (iterations, report_every) = match preset {
            Preset::Tiny => (40, 5),
            Preset::Fast => (300, 20),
            Preset::Paper => (20_000, 200),
        };
        // The axis registration is measured at tiny and fast only (README "Browser app"):
        // `paper` stays the paper's method.
        let (refine_views, rate_factor, register_magnitude) = match preset {
            Preset::Tiny | Preset::Fast => (RefineViews::All, 0.25, true),
            Preset::Paper => (RefineViews::One, 1.0, false),
        };
        Self {
            iterations,
            decide_at: 0.5,
            backward_from: 0.5,
            pixel_weight: 0.05,
            vertex_weight: 0.05,
            // The reconstruction's image loss: besides the paper's L1 + SSIM, depth and the part
            // labels say directly where a moved part belongs.
            weights: LossWeights::default(),
            gamma: 1.0,
            opacity_floor: 0.0,
            vertex: VertexMotionWeights::default(),
            rates: MotionRates::default().scaled(rate_factor),
            refine_views,
            final_rate: 0.05,
            register_magnitude,
            geometry: match preset {
                Preset::Tiny | Preset::Fast => GeometryUse::Settle,
                Preset::Paper => GeometryUse::Off,
            },
            clouds: CloudOptions::default(),
            flat_tolerance: 1e-3,
            ablation: Ablation::FULL,
            report_every,
            seed: 7,
        }
    }
}

/// The per-part joint-type decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BakeOff {
    /// Mean masked loss with the revolute / prismatic candidate (`None`: the part owns no
    /// pixel in any state-t₂ view, and the registration residuals decided instead).
    pub revolute_loss: Option<f64>,
    pub prismatic_loss: Option<f64>,
    /// Pixels of the part over all state-t₂ views.
    pub pixels: usize,
    pub kind: JointKind,
}

/// One movable part's fitted joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedJoint {
    /// The part (1 ..= K).
    pub part: usize,
    pub kind: JointKind,
    /// The fitted forward motion g⁺.
    pub motion: PartMotion,
    /// The joint in the ground-truth file's conventions.
    pub joint: GtJoint,
    /// The seeds, when the part was seen in both states.
    pub initial: Option<JointCandidates>,
    pub bake_off: BakeOff,
    /// What the axis registration changed (`None`: off, or nothing to register).
    pub axis_registration: Option<AxisRegistration>,
    /// The joint measured from the full-resolution depth and part maps (`None`: off, or the
    /// part was not measured in both states).
    pub geometry: Option<GeometricJoint>,
    /// What decided the type and the motion: `geometry`, `bake-off`, `geometry+refined`, …
    pub decided_by: &'static str,
    /// Why this joint should be checked by hand (a close type call, a part too small or
    /// unobservable in the data); `None` when nothing is known to be wrong.
    pub flag: Option<String>,
}

/// One reported point of the articulation curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArticulationPoint {
    pub iteration: u32,
    pub phase: Phase,
    /// Forward pixel-wise loss of this step's view (the mean over the views when the
    /// refinement uses them all).
    pub forward_loss: f32,
    /// Backward pixel-wise loss, when on.
    pub backward_loss: Option<f32>,
    /// Vertex-wise loss (both directions), when on.
    pub vertex_loss: Option<f64>,
}

/// Seconds per stage of the articulation phase.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ArticulationTimes {
    pub setup_s: f64,
    pub candidates_s: f64,
    pub bake_off_s: f64,
    pub refine_s: f64,
    pub total_s: f64,
}

/// The articulation field and how it was found.
#[derive(Debug, Clone, Serialize)]
pub struct Articulation {
    pub config: ArticulationConfig,
    /// One per movable part, in part order (part k ↔ joint k − 1).
    pub joints: Vec<FittedJoint>,
    /// The point revolute axis origins are reported closest to (the object's centre).
    pub center: Vec3,
    pub curve: Vec<ArticulationPoint>,
    /// Things a user should know (a part unseen in one state, one that does not move).
    pub warnings: Vec<String>,
    pub times: ArticulationTimes,
    /// The refinement step at which its objective was flat and it stopped (`None`: it ran its
    /// steps, or did not run).
    pub refine_stopped_at: Option<u32>,
}

impl Articulation {
    /// The joints in `gt/trans.json` order.
    pub fn gt_joints(&self) -> Vec<GtJoint> {
        self.joints.iter().map(|j| j.joint).collect()
    }

    /// Where the refinement started: per joint its registration seed of the fitted type, read
    /// as a joint like [`Self::gt_joints`] (`None` for a part seen in only one state).
    pub fn seed_joints(&self) -> Vec<Option<GtJoint>> {
        let center = self.center.as_dvec3();
        self.joints
            .iter()
            .map(|j| {
                let c = j.initial.as_ref()?;
                let seed = match j.kind {
                    JointKind::Revolute => c.revolute,
                    JointKind::Prismatic => c.prismatic,
                };
                Some(seed.joint(j.kind, center))
            })
            .collect()
    }
}

/// What every articulation render shares: the rasterizer and motion kernels, the render
/// settings and the image loss's weights.
struct MotionRenderer {
    raster: Rasterizer,
    kernels: MotionKernels,
    settings: RasterSettings,
    weights: LossWeights,
}

/// One state's frozen mesh, moved by the motions and rendered against the other state's views.
struct MovedView<'a> {
    field: GpuField,
    moved: MovedMesh,
    state: RasterState,
    loss: ImageLoss,
    targets: TargetImages,
    frames: &'a [Frame],
    views: ViewCycle,
}

impl<'a> MovedView<'a> {
    fn new(
        ctx: &GpuContext,
        kernels: &MotionKernels,
        field: &MeshField,
        parts: &[u32],
        frames: &'a [Frame],
    ) -> GpuResult<Self> {
        let first = frames.first().ok_or_else(|| {
            GpuError::InvalidInput("the articulation phase needs views of both states".into())
        })?;
        let (w, h) = (first.rgba.width, first.rgba.height);
        let k = field.num_parts as u32;
        let gpu = GpuField::upload(ctx, field)?;
        let moved = MovedMesh::new(ctx, kernels, &gpu, &field.positions, parts)?;
        let views: Vec<TargetView> = frames.iter().map(TargetView::from).collect();
        Ok(Self {
            state: RasterState::new(ctx, w, h, k)?,
            loss: ImageLoss::new(ctx, w, h, k)?,
            targets: TargetImages::upload(ctx, w, h, &views)?,
            field: gpu,
            moved,
            frames,
            views: ViewCycle::default(),
        })
    }

    /// Renders the mesh moved by `motions` from the view of the shuffled cycle, back-propagates
    /// the loss and reduces the position gradients: per-part sums (loss weight applied) and the
    /// loss terms' buffer filled.
    async fn step(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[(DMat3, DVec3)],
        rng: &mut Rng,
    ) -> GpuResult<Vec<PartSums>> {
        let view = self.views.next(self.frames.len(), rng);
        self.gradient(ctx, r, motions, view).await
    }

    /// A refinement step's per-part sums from one view of the cycle or the mean over every view,
    /// with the loss (the same mean) when `read_loss`.
    async fn refine_step(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[(DMat3, DVec3)],
        views: RefineViews,
        rng: &mut Rng,
        read_loss: bool,
    ) -> GpuResult<(Vec<PartSums>, Option<f32>)> {
        if views == RefineViews::One {
            let sums = self.step(ctx, r, motions, rng).await?;
            return Ok((sums, self.read_loss(ctx, read_loss).await?));
        }
        let n = self.frames.len();
        let (mut sums, mut total) = (Vec::new(), 0.0);
        for view in 0..n {
            let s = self.gradient(ctx, r, motions, view).await?;
            sums = if sums.is_empty() {
                s
            } else {
                sums.into_iter().zip(s).map(|(a, b)| a.merged(b)).collect()
            };
            total += self.read_loss(ctx, read_loss).await?.unwrap_or(0.0);
        }
        let mean = 1.0 / n.max(1) as f64;
        let sums = sums.into_iter().map(|s| s.scaled(mean)).collect();
        Ok((sums, read_loss.then_some(total * mean as f32)))
    }

    /// The last render's total loss, when `read` (a GPU readback).
    async fn read_loss(&self, ctx: &GpuContext, read: bool) -> GpuResult<Option<f32>> {
        Ok(if read {
            Some(self.loss.read_terms(ctx).await?.total)
        } else {
            None
        })
    }

    /// The loss of view `view` with the mesh moved by `motions` (terms left in the loss's
    /// buffer) and its per-part position-gradient sums.
    async fn gradient(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[(DMat3, DVec3)],
        view: usize,
    ) -> GpuResult<Vec<PartSums>> {
        self.render(ctx, r, motions, view).await?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encode_loss_and_backward(
            ctx,
            &mut encoder,
            &r.raster,
            (&self.loss, &self.targets, view),
            &mut self.state,
            &self.field,
            &r.weights,
            &r.settings,
        )?;
        self.moved.encode_reduce(ctx, &r.kernels, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
        self.moved.read_sums(ctx).await
    }

    async fn render(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[(DMat3, DVec3)],
        view: usize,
    ) -> GpuResult<()> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.moved
            .encode_apply(ctx, &r.kernels, &mut encoder, motions);
        ctx.queue.submit([encoder.finish()]);
        r.raster
            .forward(
                ctx,
                &self.field,
                &mut self.state,
                &self.frames[view].camera,
                &r.settings,
            )
            .await?;
        Ok(())
    }

    /// The bake-off's loss of the mesh moved by `motions` on the pixels labelled `part` in
    /// every view: Σ over those pixels of 0.8 |ΔRGB|₁/3 + 0.2 (1 − SSIM) + 0.5 |Δdepth| (the
    /// image loss's weights), and the pixel count.
    async fn masked_loss(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[(DMat3, DVec3)],
        part: usize,
    ) -> GpuResult<(f64, usize)> {
        let (mut sum, mut pixels) = (0.0, 0);
        for view in 0..self.frames.len() {
            let frame = &self.frames[view];
            let Some(labels) = &frame.parts else {
                continue;
            };
            let label = part as i16;
            if !labels.ids.contains(&label) {
                continue;
            }
            self.render(ctx, r, motions, view).await?;
            let render = self.state.read_render(ctx).await?;
            let (s, n) = masked_image_loss(
                &render.planes,
                frame,
                label,
                r.settings.background,
                &r.weights,
            );
            sum += s;
            pixels += n;
        }
        Ok((sum, pixels))
    }
}

/// Σ over pixels labelled `label` (part id; −1 is background) of the per-pixel image loss (see [`MovedView::masked_loss`]).
fn masked_image_loss(
    planes: &[f32],
    frame: &Frame,
    label: i16,
    background: Vec3,
    weights: &LossWeights,
) -> (f64, usize) {
    let (w, h) = (frame.rgba.width as usize, frame.rgba.height as usize);
    let n = w * h;
    // The target composited over the background exactly as the GPU loss sees it.
    let planar = super::photometric::target_rgb(frame, background);
    let target: Vec<[f64; 3]> = (0..n)
        .map(|i| [0, 1, 2].map(|c| f64::from(planar[c * n + i])))
        .collect();
    let ssim = ssim_map(planes, &target, w, h);
    let ids = frame.parts.as_ref().map(|p| &p.ids);
    let (mut sum, mut count) = (0.0, 0);
    for i in 0..n {
        if ids.is_none_or(|ids| ids[i] != label) {
            continue;
        }
        let l1 = (0..3)
            .map(|c| (f64::from(planes[c * n + i]) - target[i][c]).abs())
            .sum::<f64>()
            / 3.0;
        let mut loss = f64::from(weights.l1) * l1 + f64::from(weights.ssim) * (1.0 - ssim[i]);
        if let Some(d) = frame
            .depth
            .as_ref()
            .map(|d| d.millimetres[i])
            .filter(|&d| d > 0)
        {
            loss += f64::from(weights.depth)
                * (f64::from(planes[3 * n + i]) - f64::from(d) / 1000.0).abs();
        }
        sum += loss;
        count += 1;
    }
    (sum, count)
}

/// Per-pixel SSIM (mean over RGB) of the render's first three planes against `target`, with
/// the image loss's 11-tap Gaussian window and zero padding.
fn ssim_map(planes: &[f32], target: &[[f64; 3]], w: usize, h: usize) -> Vec<f64> {
    let taps = ssim_taps();
    let r = taps.len() / 2;
    // One separable pass along x (step 1) or y (step w), zero padding.
    let pass = |img: &[f64], along_x: bool| -> Vec<f64> {
        let mut out = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let (pos, len) = if along_x { (x, w) } else { (y, h) };
                out[y * w + x] = (0..taps.len())
                    .filter_map(|t| {
                        let q = (pos + t).checked_sub(r).filter(|&q| q < len)?;
                        Some(
                            taps[t]
                                * if along_x {
                                    img[y * w + q]
                                } else {
                                    img[q * w + x]
                                },
                        )
                    })
                    .sum();
            }
        }
        out
    };
    let blur = |img: &[f64]| pass(&pass(img, true), false);
    let n = w * h;
    let mut total = vec![0.0; n];
    for c in 0..3 {
        let a: Vec<f64> = planes[c * n..(c + 1) * n]
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        let b: Vec<f64> = target.iter().map(|t| t[c]).collect();
        let prod =
            |p: &[f64], q: &[f64]| -> Vec<f64> { p.iter().zip(q).map(|(x, y)| x * y).collect() };
        let (ma, mb) = (blur(&a), blur(&b));
        let (saa, sbb, sab) = (
            blur(&prod(&a, &a)),
            blur(&prod(&b, &b)),
            blur(&prod(&a, &b)),
        );
        for i in 0..n {
            let (va, vb, cov) = (
                saa[i] - ma[i] * ma[i],
                sbb[i] - mb[i] * mb[i],
                sab[i] - ma[i] * mb[i],
            );
            total[i] += (2.0 * ma[i] * mb[i] + SSIM_C1) * (2.0 * cov + SSIM_C2)
                / ((ma[i] * ma[i] + mb[i] * mb[i] + SSIM_C1) * (va + vb + SSIM_C2))
                / 3.0;
        }
    }
    total
}

/// Vertices of `part` in a state's field.
fn part_points(field: &MeshField, parts: &[u32], part: usize) -> Vec<Vec3> {
    field
        .positions
        .iter()
        .zip(parts)
        .filter(|(_, p)| **p as usize == part)
        .map(|(x, _)| *x)
        .collect()
}

/// Per-part forward affine maps, part 0 (the static base) fixed.
fn forward_maps(motions: &[PartMotion]) -> Vec<(DMat3, DVec3)> {
    motions.iter().map(PartMotion::forward_affine).collect()
}

fn backward_maps(motions: &[PartMotion]) -> Vec<(DMat3, DVec3)> {
    motions.iter().map(PartMotion::backward_affine).collect()
}

/// Rotations and translations below these count as "does not move".
const STILL_ANGLE_DEG: f64 = 0.5;
const STILL_DISTANCE_M: f64 = 0.002;

/// Points of the rest of the object a measured joint's axis is checked against.
const ANCHOR_POINTS: usize = 20_000;

/// Both states' clouds of a split, or `None` (no views of it, or the geometry is off).
fn observe(
    dataset: &Dataset,
    config: &ArticulationConfig,
    split: Split,
) -> Option<[ObservedState; 2]> {
    (config.geometry != GeometryUse::Off)
        .then(|| observe_dataset(dataset, split, &config.clouds))
        .flatten()
}

/// The joints the training views' depth and part maps measure, one per part (`None` for the
/// base and for a part not measured in both states).
fn measure_joints(k: usize, train: Option<&[ObservedState; 2]>) -> Vec<Option<GeometricJoint>> {
    (0..k)
        .map(|part| {
            let [s, e] = train.filter(|_| part > 0)?;
            let anchor = Anchor::new(
                &s.others(part, ANCHOR_POINTS),
                &e.others(part, ANCHOR_POINTS),
            );
            fit_joint(&s.parts[part], &e.parts[part], Some(&anchor))
        })
        .collect()
}

/// The cloud pair judging a refined joint of `part` against its measured seed: the test views'
/// (`clouds`), or `None` when either state has fewer than 3 points of the part.
fn judge(clouds: &[ObservedState; 2], part: usize) -> Option<CloudPair<'_>> {
    let [s, e] = clouds;
    let (a, b) = (&s.parts[part], &e.parts[part]);
    (a.points.len() >= 3 && b.points.len() >= 3).then(|| CloudPair::new(a, b))
}

/// What a user should know about the measurements: views without depth or part maps. A movable
/// part that no training view of either state shows (not one pixel labelled with it) is an
/// error: there is nothing to fit it to.
fn measurement_warnings(clouds: &[ObservedState; 2], warnings: &mut Vec<String>) -> GpuResult<()> {
    for (state, c) in [State::Start, State::End].iter().zip(clouds) {
        if c.views_with_depth < c.views {
            warnings.push(format!(
                "{} of the {} {} training views have no depth or part map of the colour image's size: the joints are measured from the other {}",
                c.views - c.views_with_depth,
                c.views,
                state.name(),
                c.views_with_depth
            ));
        }
    }
    let unseen: Vec<String> = (1..clouds[0].parts.len())
        .filter(|&p| clouds.iter().all(|c| c.parts[p].labelled == 0))
        .map(|p| p.to_string())
        .collect();
    if !unseen.is_empty() && clouds.iter().all(|c| c.views_with_depth > 0) {
        return Err(GpuError::InvalidInput(format!(
            "movable part(s) {} appear in no training view's part map (with depth) in either state: nothing to fit their joints to; check the semantic maps' ids (0 = background, k + 1 = part k)",
            unseen.join(", ")
        )));
    }
    Ok(())
}

/// Weight of the bake-off's evidence against the measured one. Its losses (summed over a
/// part's pixels at the working size) differ by a fraction of a percent where the measured
/// residuals differ by tens of percent; at this weight a bake-off 5 % apart outvotes a measured
/// call on the threshold, and a tie leaves the measurements to decide.
const BAKE_OFF_WEIGHT: f64 = 10.0;

/// The joint type from both models' evidence: ln(prismatic / (slack × revolute)) of the measured
/// residuals (none when the motion is not observable there) plus [`BAKE_OFF_WEIGHT`] times
/// ln(prismatic / revolute) of the bake-off's losses; positive (or zero) is revolute, as the
/// paper breaks ties.
fn combined_kind(g: &GeometricJoint, revolute_loss: f64, prismatic_loss: f64) -> JointKind {
    use crate::articulation::geometric::PRISMATIC_SLACK;
    let measured = if g.observable {
        (g.prismatic_residual / (PRISMATIC_SLACK * g.revolute_residual.max(1e-9))).ln()
    } else {
        0.0
    };
    let photometric = (prismatic_loss.max(1e-12) / revolute_loss.max(1e-12)).ln();
    if measured + BAKE_OFF_WEIGHT * photometric >= 0.0 {
        JointKind::Revolute
    } else {
        JointKind::Prismatic
    }
}

/// Why a measured (or unmeasured) joint should be checked by hand.
fn flag(geometry: Option<&GeometricJoint>, measured: bool) -> Option<String> {
    use crate::articulation::geometric::MIN_POINTS;
    let Some(g) = geometry else {
        return measured.then(|| {
            "not measured in the depth and part maps (no view shows it with depth in both states): fitted from photometry alone".to_string()
        });
    };
    if g.points.iter().any(|&n| n < MIN_POINTS) {
        Some(format!(
            "too small in the depth and part maps ({} / {} points in the two states): its joint is unreliable",
            g.points[0], g.points[1]
        ))
    } else if !g.observable {
        Some(format!(
            "its motion is not visible in the depth maps (not moving fits within {:.1} mm of either joint: a part symmetric about its axis?): type and motion come from photometry",
            1000.0 * (g.identity_residual - g.revolute_residual.min(g.prismatic_residual))
        ))
    } else if g.margin < SMALL_MARGIN {
        Some(format!(
            "joint type decided by a small margin {:.2} (revolute residual {:.2} mm, prismatic {:.2} mm)",
            g.margin,
            1000.0 * g.revolute_residual,
            1000.0 * g.prismatic_residual
        ))
    } else {
        None
    }
}

/// Runs the articulation phase on a reconstruction of `dataset` (its two states' frozen meshes
/// and training views).
pub async fn articulate(
    ctx: &GpuContext,
    dataset: &Dataset,
    rec: &Reconstruction,
    config: &ArticulationConfig,
    observer: &mut dyn Observer,
) -> GpuResult<Articulation> {
    let t0 = now_seconds();
    let mut times = ArticulationTimes::default();
    let mut warnings = Vec::new();
    let (Some(s1), Some(s2)) = (
        rec.states.iter().find(|s| s.state == State::Start),
        rec.states.iter().find(|s| s.state == State::End),
    ) else {
        return Err(GpuError::InvalidInput(
            "the articulation phase needs reconstructions of both states".into(),
        ));
    };
    let k = rec.num_parts;
    let views1 =
        training_views(dataset, State::Start, &rec.config).map_err(GpuError::InvalidInput)?;
    let views2 =
        training_views(dataset, State::End, &rec.config).map_err(GpuError::InvalidInput)?;
    let kernels = MotionKernels::new(ctx);
    // Forward: state t₁'s mesh, moved by g⁺, against state t₂'s views; backward the reverse.
    let mut forward = MovedView::new(ctx, &kernels, &s1.field, &s1.parts, &views2)?;
    let mut backward = MovedView::new(ctx, &kernels, &s2.field, &s2.parts, &views1)?;
    let surface1 = StateSurface::from_field(&s1.field).map_err(GpuError::InvalidInput)?;
    let surface2 = StateSurface::from_field(&s2.field).map_err(GpuError::InvalidInput)?;
    let recovery = rec.config.recovery();
    let renderer = MotionRenderer {
        raster: Rasterizer::new(ctx),
        kernels,
        settings: RasterSettings {
            gamma: config.gamma,
            opacity_floor: config.opacity_floor,
            ..recovery.settings_at(recovery.iterations)
        },
        weights: config.weights,
    };
    let center = principal_frame(&s1.field.positions).map_or(DVec3::ZERO, |f| f.centroid);

    // Seeds.
    let candidates: Vec<Option<JointCandidates>> = (0..k)
        .map(|part| {
            if part == 0 {
                return None;
            }
            let a = part_points(&s1.field, &s1.parts, part);
            let b = part_points(&s2.field, &s2.parts, part);
            let seeds = initial_candidates(&a, &b);
            if seeds.is_none() {
                let missing = if a.len() < 3 { "start" } else { "end" };
                warnings.push(format!(
                    "part {part} has no reconstructed surface in the {missing} state: its joint cannot be fitted and is reported as a motionless revolute joint"
                ));
            }
            seeds
        })
        .collect();
    let pick = |f: fn(&JointCandidates) -> PartMotion| -> Vec<PartMotion> {
        candidates
            .iter()
            .map(|c| c.as_ref().map_or(PartMotion::IDENTITY, f))
            .collect()
    };
    let mut revolute = pick(|c| c.revolute);
    let mut prismatic = pick(|c| c.prismatic);
    // The measured joints: seeds where there are, and the settled parts out of the photometry.
    let train_clouds = observe(dataset, config, Split::Train);
    if let Some(clouds) = &train_clouds {
        measurement_warnings(clouds, &mut warnings)?;
        let has_test_views = [State::Start, State::End]
            .iter()
            .all(|&s| dataset.views(s, Split::Test).is_some());
        if !has_test_views {
            warnings.push(
                "the dataset has no test views: refined joints are judged against their measured seeds on the training views' points".into(),
            );
        }
    }
    let measured = measure_joints(k, train_clouds.as_ref());
    let settled: Vec<bool> = measured
        .iter()
        .map(|g| config.geometry == GeometryUse::Settle && g.is_some_and(|g| g.settled()))
        .collect();
    for part in 1..k {
        if let Some(g) = &measured[part] {
            revolute[part] = g.revolute;
            prismatic[part] = g.prismatic;
        }
    }
    let trainable: Vec<bool> = (0..k)
        .map(|p| candidates[p].is_some() && !settled[p])
        .collect();
    times.setup_s = now_seconds() - t0;

    // No part left for photometry: no photometric step at all.
    let photometric = trainable.iter().any(|&t| t);
    let n = if photometric { config.iterations } else { 0 };
    let decide = config.decision_step().min(n);
    let backward_from = (n as f32 * config.backward_from) as u32;
    let mut rng = Rng::new(config.seed);
    let mut curve = Vec::new();
    let event = |phase: Phase, iteration: u32, iterations: u32, loss: Option<f32>| Progress {
        state: State::End,
        phase,
        iteration,
        iterations,
        loss,
        psnr: None,
        vertices: s1.field.num_vertices() + s2.field.num_vertices(),
        faces: s1.field.faces.len() + s2.field.faces.len(),
        elapsed_s: now_seconds() - t0,
    };
    checkpoint(observer, &event(Phase::Candidates, 0, decide, None)).await?;

    // 1. Candidates, alternating.
    let mut adam_rot = MotionAdam::new(k, config.rates);
    let mut adam_trans = MotionAdam::new(k, config.rates);
    let t_candidates = now_seconds();
    for i in 0..decide {
        let is_rot = i % 2 == 0;
        let decay = config
            .final_rate
            .powf(f64::from(i) / f64::from(decide.max(1)));
        adam_rot.set_scale(decay);
        adam_trans.set_scale(decay);
        let (motions, adam, kind) = if is_rot {
            (&mut revolute, &mut adam_rot, JointKind::Revolute)
        } else {
            (&mut prismatic, &mut adam_trans, JointKind::Prismatic)
        };
        let sums_f = forward
            .step(ctx, &renderer, &forward_maps(motions), &mut rng)
            .await?;
        let with_backward = config.ablation.backward && i >= backward_from;
        let sums_b = if with_backward {
            backward
                .step(ctx, &renderer, &backward_maps(motions), &mut rng)
                .await?
        } else {
            vec![PartSums::default(); k]
        };
        for part in (1..k).filter(|&p| trainable[p]) {
            let g = motions[part].gradient(
                &sums_f[part].scaled(config.pixel_weight),
                &sums_b[part].scaled(config.pixel_weight),
            );
            adam.step(part, &mut motions[part], &g, MotionMask::of(kind));
        }
        if (i + 1).is_multiple_of(config.report_every.max(1)) || i + 1 == decide {
            let terms = forward.loss.read_terms(ctx).await?;
            curve.push(ArticulationPoint {
                iteration: i,
                phase: Phase::Candidates,
                forward_loss: terms.total,
                backward_loss: None,
                vertex_loss: None,
            });
            checkpoint(
                observer,
                &event(Phase::Candidates, i + 1, decide, Some(terms.total)),
            )
            .await?;
        }
    }
    times.candidates_s = now_seconds() - t_candidates;

    // 2. Bake-off.
    let t_bake = now_seconds();
    checkpoint(observer, &event(Phase::BakeOff, 0, (k - 1) as u32, None)).await?;
    let mut kinds: Vec<JointKind> = (0..k)
        .map(|p| measured[p].map_or(JointKind::Revolute, |g| g.kind))
        .collect();
    let mut bake_offs: Vec<BakeOff> = kinds
        .iter()
        .map(|&kind| BakeOff {
            revolute_loss: None,
            prismatic_loss: None,
            pixels: 0,
            kind,
        })
        .collect();
    for part in (1..k).filter(|&p| trainable[p]) {
        let only = |m: PartMotion| -> Vec<(DMat3, DVec3)> {
            (0..k)
                .map(|p| if p == part { m } else { PartMotion::IDENTITY }.forward_affine())
                .collect()
        };
        let (rot, pixels) = forward
            .masked_loss(ctx, &renderer, &only(revolute[part]), part)
            .await?;
        let (trans, _) = forward
            .masked_loss(ctx, &renderer, &only(prismatic[part]), part)
            .await?;
        let c = candidates[part]
            .as_ref()
            .expect("trainable parts have candidates");
        let kind = if pixels > 0 {
            if rot <= trans {
                JointKind::Revolute
            } else {
                JointKind::Prismatic
            }
        } else {
            warnings.push(format!(
                "part {part} owns no pixel in any end-state view: its joint type is decided by the registration residuals instead"
            ));
            if c.registration.residual <= c.prismatic_residual {
                JointKind::Revolute
            } else {
                JointKind::Prismatic
            }
        };
        // Both models' evidence: the measured residuals' and the bake-off's log ratios.
        let kind = match &measured[part] {
            Some(g) if pixels > 0 => combined_kind(g, rot, trans),
            Some(g) if g.observable => g.kind,
            _ => kind,
        };
        kinds[part] = kind;
        bake_offs[part] = BakeOff {
            revolute_loss: (pixels > 0).then(|| rot / pixels as f64),
            prismatic_loss: (pixels > 0).then(|| trans / pixels as f64),
            pixels,
            kind,
        };
        checkpoint(
            observer,
            &event(Phase::BakeOff, part as u32, (k - 1) as u32, None),
        )
        .await?;
    }
    let mut motions: Vec<PartMotion> = (0..k)
        .map(|p| match kinds[p] {
            _ if !trainable[p] && !settled[p] => PartMotion::IDENTITY,
            JointKind::Revolute => revolute[p],
            JointKind::Prismatic => prismatic[p],
        })
        .collect();
    times.bake_off_s = now_seconds() - t_bake;

    // 3. Refine the winners, fresh moments, type-masked.
    let t_refine = now_seconds();
    let mut adam = MotionAdam::new(k, config.rates);
    let vertex = VertexMotionWeights {
        color: if config.ablation.vertex_color {
            config.vertex.color
        } else {
            0.0
        },
        opacity: if config.ablation.vertex_opacity {
            config.vertex.opacity
        } else {
            0.0
        },
        ..config.vertex
    };
    let vertex_on = vertex.color > 0.0 || vertex.opacity > 0.0;
    let refine = n - decide;
    checkpoint(observer, &event(Phase::Refine, 0, refine, None)).await?;
    let (mut last_objective, mut refine_stopped_at) = (None::<f64>, None);
    for i in decide..n {
        adam.set_scale(
            config
                .final_rate
                .powf(f64::from(i - decide) / f64::from(refine.max(1))),
        );
        // This step's affine maps, both directions, shared by the pixel- and vertex-wise terms.
        let (g_fwd, g_bwd) = (forward_maps(&motions), backward_maps(&motions));
        let step = i - decide;
        let report = (step + 1).is_multiple_of(config.report_every.max(1)) || i + 1 == n;
        let views = config.refine_views;
        let (sums_f, forward_loss) = forward
            .refine_step(ctx, &renderer, &g_fwd, views, &mut rng, report)
            .await?;
        let with_backward = config.ablation.backward && i >= backward_from;
        let (sums_b, backward_loss) = if with_backward {
            backward
                .refine_step(ctx, &renderer, &g_bwd, views, &mut rng, report)
                .await?
        } else {
            (vec![PartSums::default(); k], None)
        };
        let mut vertex_loss = None;
        let (mut vf, mut vb) = (vec![PartSums::default(); k], vec![PartSums::default(); k]);
        if vertex_on {
            let f = vertex_motion_loss(&surface1, &surface2, &g_fwd, &vertex)
                .map_err(GpuError::InvalidInput)?;
            let mut total = f.loss;
            vf = f.per_part;
            if config.ablation.backward {
                let b = vertex_motion_loss(&surface2, &surface1, &g_bwd, &vertex)
                    .map_err(GpuError::InvalidInput)?;
                total += b.loss;
                vb = b.per_part;
            }
            vertex_loss = Some(total);
        }
        for part in (1..k).filter(|&p| trainable[p]) {
            let fw = sums_f[part]
                .scaled(config.pixel_weight)
                .merged(vf[part].scaled(config.vertex_weight));
            let bw = sums_b[part]
                .scaled(config.pixel_weight)
                .merged(vb[part].scaled(config.vertex_weight));
            let g = motions[part].gradient(&fw, &bw);
            adam.step(part, &mut motions[part], &g, MotionMask::of(kinds[part]));
        }
        // Read back only on report steps.
        if let Some(forward_loss) = forward_loss {
            curve.push(ArticulationPoint {
                iteration: i,
                phase: Phase::Refine,
                forward_loss,
                backward_loss,
                vertex_loss,
            });
            checkpoint(
                observer,
                &event(Phase::Refine, step + 1, refine, Some(forward_loss)),
            )
            .await?;
            // Flat: the reported objective moved by less than the tolerance since the last report.
            let objective = f64::from(forward_loss)
                + f64::from(backward_loss.unwrap_or(0.0))
                + vertex_loss.unwrap_or(0.0);
            if let Some(before) = last_objective {
                let change: f64 = (objective - before) / f64::max(f64::abs(before), 1e-12);
                if change.abs() < config.flat_tolerance && i + 1 < n {
                    refine_stopped_at = Some(step + 1);
                    break;
                }
            }
            last_objective = Some(objective);
        }
    }
    times.refine_s = now_seconds() - t_refine;

    // The clouds that judge refined joints against their measured seeds, observed only when a
    // measured joint was refined: the test views', else the training views'.
    let refined_measured = (1..k).any(|p| trainable[p] && measured[p].is_some());
    let test_clouds = refined_measured
        .then(|| observe(dataset, config, Split::Test))
        .flatten();
    let judging = test_clouds.as_ref().or(train_clouds.as_ref());

    let joints: Vec<FittedJoint> = (1..k)
        .map(|part| {
            let geometry = measured[part];
            let kind = kinds[part];
            let (mut motion, mut axis_registration) =
                if config.register_magnitude && trainable[part] {
                    register_along_axis(motions[part], kind, &surface1, &surface2, part)
                } else {
                    (motions[part], None)
                };
            let mut decided_by = if settled[part] {
                "geometry"
            } else if trainable[part] {
                "bake-off+refined"
            } else {
                "none"
            };
            // Never worse than the measured seed on the held-out measurements.
            let pair = judging
                .filter(|_| trainable[part])
                .and_then(|c| judge(c, part));
            if let (Some(g), Some(pair)) = (geometry, pair) {
                let seed = g.motion(kind);
                if pair.residual(&seed) < pair.residual(&motion) {
                    motion = seed;
                    axis_registration = None;
                    decided_by = "geometry (kept over the refinement)";
                }
            }
            let flag = flag(geometry.as_ref(), config.geometry != GeometryUse::Off);
            FittedJoint {
                part,
                kind,
                motion,
                joint: motion.joint(kind, center),
                initial: candidates[part],
                bake_off: bake_offs[part],
                axis_registration,
                geometry,
                decided_by,
                flag,
            }
        })
        .collect();
    for j in &joints {
        if let Some(f) = &j.flag {
            warnings.push(format!("part {}: {f}", j.part));
        }
    }
    for j in &joints {
        let tiny = match j.kind {
            JointKind::Revolute => f64::from(j.joint.motion().abs()) < STILL_ANGLE_DEG,
            JointKind::Prismatic => f64::from(j.joint.motion().abs()) < STILL_DISTANCE_M,
        };
        let unresolved = j
            .initial
            .as_ref()
            .is_some_and(JointCandidates::barely_moves);
        // The measurements saw it move: the reconstructions' view does not count.
        let seen_moving = j.geometry.is_some_and(|g| g.observable);
        if ((tiny && j.initial.is_some()) || unresolved) && !seen_moving {
            warnings.push(format!(
                "part {} barely moves between the states (fitted {:.3} {}; not moving at all fits its two reconstructions about as well): its axis and joint type are guesses",
                j.part,
                j.joint.motion(),
                if j.kind == JointKind::Revolute { "°" } else { "m" }
            ));
        }
    }
    times.total_s = now_seconds() - t0;
    checkpoint(observer, &event(Phase::Done, refine, refine, None)).await?;
    Ok(Articulation {
        config: *config,
        joints,
        center: center.as_vec3(),
        curve,
        warnings,
        times,
        refine_stopped_at,
    })
}
