//! The GPU side of the articulation: one state's frozen mesh moved by the parts' rigid
//! motions ([`MovedView`]), rendered from the other state's cameras and compared with its
//! views; what comes back are the per-part position-gradient sums of the pixel-wise motion
//! consistency, or the bake-off's per-part masked loss.

use glam::{DMat3, DVec3, Vec3};

use super::config::{ArticulationConfig, RefineViews};
use super::ssim::masked_image_loss;
use crate::articulation::kernels::{MotionKernels, MovedMesh};
use crate::articulation::{PartMotion, PartSums};
use crate::data::{Frame, JointKind};
use crate::fit::observer::{AxisMark, Marks};
use crate::fit::photometric::{encode_loss_and_backward, planes_to_rgb8, target_rgb};
use crate::fit::reconstruct::ReconstructionConfig;
use crate::fit::views::ViewCycle;
use crate::gpu::{GpuContext, GpuError, GpuResult};
use crate::loss::{ImageLoss, LossWeights, TargetImages, TargetView};
use crate::raster::{GpuField, MeshField, RasterSettings, RasterState, Rasterizer, RenderImages};
use crate::rng::Rng;

/// Per-part forward affine maps, part 0 (the static base) fixed.
pub(super) fn forward_maps(motions: &[PartMotion]) -> Vec<(DMat3, DVec3)> {
    motions.iter().map(PartMotion::forward_affine).collect()
}

/// Per-part backward affine maps (the analytic inverses g⁻).
pub(super) fn backward_maps(motions: &[PartMotion]) -> Vec<(DMat3, DVec3)> {
    motions.iter().map(PartMotion::backward_affine).collect()
}

/// What every articulation render shares: the rasterizer and motion kernels, the render
/// settings and the image loss's weights.
pub(super) struct MotionRenderer {
    raster: Rasterizer,
    kernels: MotionKernels,
    settings: RasterSettings,
    weights: LossWeights,
}

impl MotionRenderer {
    /// The renderer of the articulation: the reconstruction's final render settings (its
    /// recovery's last) with the articulation's softer window and opacity floor.
    pub(super) fn new(
        ctx: &GpuContext,
        kernels: MotionKernels,
        rec: &ReconstructionConfig,
        config: &ArticulationConfig,
    ) -> Self {
        let recovery = rec.recovery();
        Self {
            raster: Rasterizer::new(ctx),
            kernels,
            settings: RasterSettings {
                gamma: config.gamma,
                opacity_floor: config.opacity_floor,
                ..recovery.settings_at(recovery.iterations)
            },
            weights: config.weights,
        }
    }
}

/// One state's frozen mesh, moved by the motions and rendered against the other state's views.
pub(super) struct MovedView<'a> {
    field: GpuField,
    moved: MovedMesh,
    state: RasterState,
    /// The image loss, whose terms buffer holds the last render's loss.
    pub(super) loss: ImageLoss,
    targets: TargetImages,
    frames: &'a [Frame],
    views: ViewCycle,
    /// Per part its rest centroid and size (1.5 × RMS distance to it), where axes are drawn.
    centres: Vec<(DVec3, f64)>,
}

/// A picture of the moved mesh: width, height, the render and the photo (RGB8) and the marks.
pub(super) struct Snapshot {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) render: Vec<u8>,
    pub(super) target: Vec<u8>,
    pub(super) marks: Marks,
}

impl<'a> MovedView<'a> {
    /// The mesh `field` (hardened `parts`) against `frames`, the other state's views.
    pub(super) fn new(
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
            centres: part_centres(&field.positions, parts, field.num_parts),
        })
    }

    /// Renders the mesh moved by `motions` from the view of the shuffled cycle, back-propagates
    /// the loss and reduces the position gradients: per-part sums (loss weight applied) and the
    /// loss terms' buffer filled.
    pub(super) async fn step(
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
    pub(super) async fn refine_step(
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

    /// Moves the mesh by `motions` and renders it from view `view`.
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

    /// The view that sees `part` most (by its labelled pixels; view 0 when none labels it).
    pub(super) fn view_showing(&self, part: usize) -> usize {
        let label = part as i16;
        let pixels = |f: &Frame| {
            f.parts
                .as_ref()
                .map_or(0, |p| p.ids.iter().filter(|&&id| id == label).count())
        };
        (0..self.frames.len())
            .max_by_key(|&v| (pixels(&self.frames[v]), std::cmp::Reverse(v)))
            .unwrap_or(0)
    }

    /// The mesh moved forward by `motions`, rendered from view `view`, beside that view's photo
    /// (composited on the background), with each pixel's part and the moved parts' axes.
    pub(super) async fn snapshot(
        &mut self,
        ctx: &GpuContext,
        r: &MotionRenderer,
        motions: &[PartMotion],
        view: usize,
    ) -> GpuResult<Snapshot> {
        self.render(ctx, r, &forward_maps(motions), view).await?;
        let render = self.state.read_render(ctx).await?;
        let n = (render.width * render.height) as usize;
        let target = target_rgb(&self.frames[view], r.settings.background);
        let camera = &self.frames[view].camera;
        Ok(Snapshot {
            width: render.width,
            height: render.height,
            render: planes_to_rgb8(&render.planes[..3 * n]),
            target: planes_to_rgb8(&target),
            marks: Marks {
                parts: part_labels(&render),
                axes: axis_marks(motions, &self.centres, |p| {
                    camera.project(p.as_vec3()).map(|(px, _)| px.to_array())
                }),
            },
        })
    }

    /// The bake-off's loss of the mesh moved by `motions` on the pixels labelled `part` in
    /// every view: Σ over those pixels of 0.8 |ΔRGB|₁/3 + 0.2 (1 − SSIM) + 0.5 |Δdepth| (the
    /// image loss's weights), and the pixel count.
    pub(super) async fn masked_loss(
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

/// Per part its centroid and size (1.5 × RMS distance of its vertices to it; 0 when empty).
fn part_centres(positions: &[Vec3], parts: &[u32], k: usize) -> Vec<(DVec3, f64)> {
    let mut sums = vec![(DVec3::ZERO, 0.0, 0usize); k];
    for (x, &p) in positions.iter().zip(parts) {
        if let Some(s) = sums.get_mut(p as usize) {
            s.0 += x.as_dvec3();
            s.1 += x.as_dvec3().length_squared();
            s.2 += 1;
        }
    }
    sums.into_iter()
        .map(|(sum, sq, n)| {
            let n = n.max(1) as f64;
            let c = sum / n;
            (c, 1.5 * (sq / n - c.length_squared()).max(0.0).sqrt())
        })
        .collect()
}

/// Each pixel's part: the largest part logit where the render is mostly opaque.
fn part_labels(render: &RenderImages) -> Vec<u8> {
    let alpha = render.plane(4);
    (0..alpha.len())
        .map(|i| {
            if alpha[i] < 0.5 {
                return Marks::EMPTY;
            }
            (0..render.num_parts.min(usize::from(Marks::EMPTY)))
                .max_by(|&a, &b| render.plane(5 + a)[i].total_cmp(&render.plane(5 + b)[i]))
                .map_or(Marks::EMPTY, |p| p as u8)
        })
        .collect()
}

/// The moved parts' axes through `project` (world → pixel; `None` behind the camera): a part
/// that turns more than a quarter degree is drawn as a hinge, one that only moves as a slide.
fn axis_marks(
    motions: &[PartMotion],
    centres: &[(DVec3, f64)],
    project: impl Fn(DVec3) -> Option<[f32; 2]>,
) -> Vec<AxisMark> {
    let mut marks = Vec::new();
    for (part, (m, &(centre, size))) in motions.iter().zip(centres).enumerate().skip(1) {
        let (_, angle) = m.axis_and_magnitude(JointKind::Revolute);
        let (direction, distance) = m.axis_and_magnitude(JointKind::Prismatic);
        let (kind, from, to) = if angle > 0.25f64.to_radians() {
            let j = m.joint(JointKind::Revolute, centre);
            let (o, d) = (j.origin.as_dvec3(), j.direction.as_dvec3());
            (JointKind::Revolute, o - d * size, o + d * size)
        } else if distance > 1e-6 {
            let length = distance.max(0.5 * size);
            (JointKind::Prismatic, centre, centre + direction * length)
        } else {
            continue; // still: nothing to draw
        };
        if let (Some(from), Some(to)) = (project(from), project(to)) {
            marks.push(AxisMark {
                part,
                kind,
                from,
                to,
            });
        }
    }
    marks
}
