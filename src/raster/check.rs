//! Checks of the rasterizer that run the same way natively (lavapipe) and in the browser
//! (SwiftShader): the GPU forward pass against the CPU [`reference`](super::reference), and the
//! backward pass against central finite differences of the forward pass, per parameter group.
//!
//! The gradient check differentiates the linear functional L = Σ G ⊙ O of the rendered planes O
//! (RGB, depth, alpha, part logits) with random weights G, so every output channel is exercised;
//! the loss terms are checked separately against their own finite differences (`loss`).

use glam::Vec3;
use serde::Serialize;

use super::field::{GpuField, MeshField, SH_FLOATS};
use super::rasterizer::Rasterizer;
use super::reference;
use super::settings::{BASE_CHANNELS, RasterSettings};
use super::state::{RasterState, RenderImages};
use crate::data::{Camera, look_at};
use crate::gpu::{GpuContext, GpuResult};
use crate::rng::Rng;

/// A small scene: a bumpy 4×4-vertex grid (shared vertices) with a second, partly transparent
/// layer of triangles in front of it (overlapping faces), on a 40×28 image (partial tiles, pixels
/// partly covered by soft faces), three parts, SH degree 3.
#[derive(Debug, Clone)]
pub struct Scene {
    pub field: MeshField,
    pub camera: Camera,
    pub settings: RasterSettings,
}

/// The check scene for `seed`.
pub fn scene(seed: u64, width: u32, height: u32) -> Scene {
    let mut rng = Rng::new(seed);
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let n = 4;
    for j in 0..n {
        for i in 0..n {
            let x = -0.6 + 1.2 * i as f32 / (n - 1) as f32 + rng.uniform(-0.05, 0.05);
            let z = -0.6 + 1.2 * j as f32 / (n - 1) as f32 + rng.uniform(-0.05, 0.05);
            positions.push(Vec3::new(x, rng.uniform(-0.1, 0.1), z));
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as u32;
            let row = n as u32;
            faces.push([v, v + 1, v + row + 1]);
            faces.push([v, v + row + 1, v + row]);
        }
    }
    // Front layer: a fan of three triangles around a shared centre vertex.
    let centre = positions.len() as u32;
    positions.push(Vec3::new(0.1, -0.4, 0.05));
    for k in 0..4 {
        let angle = 0.3 + k as f32 * 1.4;
        positions.push(Vec3::new(
            0.1 + 0.55 * angle.cos(),
            -0.4 + rng.uniform(-0.05, 0.05),
            0.05 + 0.5 * angle.sin(),
        ));
    }
    for k in 0..3u32 {
        faces.push([centre, centre + 1 + k, centre + 2 + k]);
    }
    let num_parts = 3;
    let mut field = MeshField::new(positions, faces, num_parts, 0.0);
    for v in field.sh.iter_mut() {
        *v = rng.uniform(-0.4, 0.4);
    }
    for o in field.opacity.iter_mut() {
        *o = rng.uniform(-1.0, 1.2);
    }
    for s in field.part_logits.iter_mut() {
        *s = rng.uniform(-1.5, 1.5);
    }
    let eye = Vec3::new(0.3, -2.6, 0.6);
    let camera = Camera::from_fov(look_at(eye, Vec3::ZERO, Vec3::Z), width, height, 0.75, None);
    let settings = RasterSettings {
        gamma: 1.0,
        background: Vec3::new(0.2, 0.3, 0.4),
        sh_degree: 3,
        ..RasterSettings::default()
    };
    Scene {
        field,
        camera,
        settings,
    }
}

/// GPU forward vs CPU reference.
#[derive(Debug, Clone, Serialize)]
pub struct ReferenceCheck {
    pub gamma: f32,
    /// Largest |GPU − CPU| over RGB and alpha.
    pub max_abs_color: f32,
    /// Largest |GPU − CPU| of the expected depth (metres).
    pub max_abs_depth: f32,
    /// Largest |GPU − CPU| of the composited part logits.
    pub max_abs_logits: f32,
    /// Fraction of pixels with alpha > 0.01 (the scene is not empty).
    pub coverage: f32,
    /// Largest |GPU − CPU| of the per-face maximum blending weight.
    pub max_abs_face_weight: f32,
    /// Faces whose pixel count differs between GPU and CPU (of `faces`).
    pub face_count_mismatches: usize,
    pub faces: usize,
    pub tolerance: f32,
}

impl ReferenceCheck {
    pub fn passed(&self) -> bool {
        self.coverage > 0.2
            && self.max_abs_color <= self.tolerance
            && self.max_abs_depth <= self.tolerance
            && self.max_abs_logits <= self.tolerance
            && self.max_abs_face_weight <= self.tolerance
            && self.face_count_mismatches == 0
    }
}

/// Renders `scene` on the GPU and on the CPU and compares every plane.
pub async fn check_reference(
    ctx: &GpuContext,
    scene: &Scene,
    tolerance: f32,
) -> GpuResult<ReferenceCheck> {
    let raster = Rasterizer::new(ctx);
    let field = GpuField::upload(ctx, &scene.field)?;
    let k = scene.camera.intrinsics;
    let mut state = RasterState::new(ctx, k.width, k.height, scene.field.num_parts as u32)?;
    raster
        .forward(ctx, &field, &mut state, &scene.camera, &scene.settings)
        .await?;
    let gpu = state.read_render(ctx).await?;
    let gpu_stats = state.read_face_stats(ctx, field.num_faces).await?;
    let (cpu, cpu_stats) =
        reference::render_with_stats(&scene.field, &scene.camera, &scene.settings);
    let max_diff = |planes: std::ops::Range<usize>| {
        planes
            .flat_map(|c| {
                gpu.plane(c)
                    .iter()
                    .zip(cpu.plane(c))
                    .map(|(a, b)| (a - b).abs())
            })
            .fold(0.0f32, f32::max)
    };
    let alpha = gpu.plane(4);
    Ok(ReferenceCheck {
        gamma: scene.settings.gamma,
        max_abs_color: max_diff(0..3).max(max_diff(4..5)),
        max_abs_depth: max_diff(3..4),
        max_abs_logits: max_diff(BASE_CHANNELS..BASE_CHANNELS + gpu.num_parts),
        coverage: alpha.iter().filter(|&&a| a > 0.01).count() as f32 / alpha.len() as f32,
        max_abs_face_weight: gpu_stats
            .iter()
            .zip(&cpu_stats)
            .map(|(g, c)| (g.0 - c.0).abs())
            .fold(0.0, f32::max),
        face_count_mismatches: gpu_stats
            .iter()
            .zip(&cpu_stats)
            .filter(|(g, c)| g.1 != c.1)
            .count(),
        faces: cpu_stats.len(),
        tolerance,
    })
}

/// Finite-difference agreement of one parameter group.
#[derive(Debug, Clone, Serialize)]
pub struct GroupCheck {
    pub group: String,
    pub checked: usize,
    /// Elements outside `|fd − g| ≤ rtol · max(|fd|, |g|) + atol · max_group |g|`.
    pub failed: usize,
    /// ‖fd − g‖ / ‖fd‖ over the group.
    pub relative_l2: f64,
    /// Largest |fd − g| / max(|fd|, |g|) among elements with a non-negligible gradient.
    pub max_relative: f64,
    /// Largest |g| in the group (it must not be trivially zero).
    pub max_gradient: f64,
    pub rtol: f64,
    pub atol: f64,
}

impl GroupCheck {
    pub fn passed(&self) -> bool {
        self.failed == 0 && self.relative_l2 < self.rtol && self.max_gradient > 0.0
    }
}

/// The parameter groups a gradient check covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Group {
    Positions,
    ShBand(u32),
    Opacity,
    PartLogits,
}

impl Group {
    fn name(self) -> String {
        match self {
            Group::Positions => "positions".into(),
            Group::ShBand(l) => format!("sh band {l}"),
            Group::Opacity => "opacity".into(),
            Group::PartLogits => "part logits".into(),
        }
    }
}

/// Finite-difference step for positions (metres; about 1/1500 of a pixel in the check scene):
/// small enough that pixel centres rarely fall between the two sides of a kink of the window
/// (its edges and medial axes), large enough for f32 renders.
const POSITION_STEP: f32 = 3e-5;

/// One checked element: group, flat index into that group's array, step.
struct Probe {
    group: Group,
    index: usize,
    step: f32,
}

fn linear_functional(render: &RenderImages, weights: &[f32]) -> f64 {
    render
        .planes
        .iter()
        .zip(weights)
        .map(|(o, g)| f64::from(*o) * f64::from(*g))
        .sum()
}

/// The elements to check: every position and opacity, `probes_per_group` random entries of each SH
/// band and of the part logits (drawn from `rng` in that order).
fn gradient_probes(nv: usize, parts: usize, probes_per_group: usize, rng: &mut Rng) -> Vec<Probe> {
    let mut probes = Vec::new();
    for i in 0..nv * 3 {
        probes.push(Probe {
            group: Group::Positions,
            index: i,
            step: POSITION_STEP,
        });
    }
    for band in 0..=3u32 {
        let coeffs = band * band..(band + 1) * (band + 1);
        for _ in 0..probes_per_group {
            let v = rng.below(nv as u32) as usize;
            let c = coeffs.start + rng.below(coeffs.end - coeffs.start);
            let channel = rng.below(3) as usize;
            probes.push(Probe {
                group: Group::ShBand(band),
                index: v * SH_FLOATS + 3 * c as usize + channel,
                step: 1e-2,
            });
        }
    }
    for i in 0..nv {
        probes.push(Probe {
            group: Group::Opacity,
            index: i,
            step: 1e-2,
        });
    }
    for _ in 0..probes_per_group.max(1) {
        probes.push(Probe {
            group: Group::PartLogits,
            index: rng.below((nv * parts) as u32) as usize,
            step: 1e-2,
        });
    }
    probes
}

/// Per-group agreement of (group, finite difference, analytic) rows, groups in first-seen order.
fn summarise(results: &[(Group, f64, f64)]) -> Vec<GroupCheck> {
    let (rtol, atol) = (2e-2, 2e-3);
    let mut groups: Vec<Group> = Vec::new();
    for (g, _, _) in results {
        if !groups.contains(g) {
            groups.push(*g);
        }
    }
    groups
        .into_iter()
        .map(|group| {
            let rows: Vec<_> = results.iter().filter(|r| r.0 == group).collect();
            let max_gradient = rows
                .iter()
                .map(|r| r.2.abs().max(r.1.abs()))
                .fold(0.0, f64::max);
            let failed = rows
                .iter()
                .filter(|r| {
                    (r.1 - r.2).abs() > rtol * r.1.abs().max(r.2.abs()) + atol * max_gradient
                })
                .count();
            let err2: f64 = rows.iter().map(|r| (r.1 - r.2).powi(2)).sum();
            let ref2: f64 = rows.iter().map(|r| r.1.powi(2)).sum();
            let max_relative = rows
                .iter()
                .filter(|r| r.1.abs().max(r.2.abs()) > 1e-2 * max_gradient)
                .map(|r| (r.1 - r.2).abs() / r.1.abs().max(r.2.abs()))
                .fold(0.0, f64::max);
            GroupCheck {
                group: group.name(),
                checked: rows.len(),
                failed,
                relative_l2: (err2 / ref2.max(1e-300)).sqrt(),
                max_relative,
                max_gradient,
                rtol,
                atol,
            }
        })
        .collect()
}

/// Central finite differences of L = Σ G ⊙ O for every parameter group of `scene`, with the
/// hard cut-offs smoothed away ([`RasterSettings::smooth`]). `probes_per_group` caps the number of
/// elements checked per group (positions, opacity and small groups are checked whole).
pub async fn check_gradients(
    ctx: &GpuContext,
    scene: &Scene,
    seed: u64,
    probes_per_group: usize,
) -> GpuResult<Vec<GroupCheck>> {
    let settings = scene.settings.smooth();
    let raster = Rasterizer::new(ctx);
    let field = GpuField::upload(ctx, &scene.field)?;
    let k = scene.camera.intrinsics;
    let parts = scene.field.num_parts;
    let mut state = RasterState::new(ctx, k.width, k.height, parts as u32)?;
    let npix = (k.width * k.height) as usize;
    let mut rng = Rng::new(seed);
    let weights: Vec<f32> = (0..(BASE_CHANNELS + parts) * npix)
        .map(|_| rng.uniform(-1.0, 1.0))
        .collect();

    raster
        .forward(ctx, &field, &mut state, &scene.camera, &settings)
        .await?;
    ctx.queue
        .write_buffer(state.grad_render(), 0, bytemuck::cast_slice(&weights));
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    raster.encode_backward(ctx, &mut encoder, &field, &mut state);
    ctx.queue.submit([encoder.finish()]);
    let grads = field.read_gradients(ctx).await?;

    let nv = scene.field.num_vertices();
    let probes = gradient_probes(nv, parts, probes_per_group, &mut rng);

    let mut results: Vec<(Group, f64, f64)> = Vec::new();
    for probe in &probes {
        let (buffer, base_value, offset, analytic) = match probe.group {
            Group::Positions => {
                let (v, axis) = (probe.index / 3, probe.index % 3);
                (
                    &field.positions,
                    scene.field.positions[v][axis],
                    (v * 4 + axis) * 4,
                    grads.positions[v][axis],
                )
            }
            Group::ShBand(_) => (
                &field.sh,
                scene.field.sh[probe.index],
                probe.index * 4,
                grads.sh[probe.index],
            ),
            Group::Opacity => (
                &field.opacity,
                scene.field.opacity[probe.index],
                probe.index * 4,
                grads.opacity[probe.index],
            ),
            Group::PartLogits => (
                &field.part_logits,
                scene.field.part_logits[probe.index],
                probe.index * 4,
                grads.part_logits[probe.index],
            ),
        };
        let mut side = [0.0f64; 2];
        // The f32 values actually set, so their rounding does not enter the quotient.
        let values = [base_value + probe.step, base_value - probe.step];
        for (s, &value) in values.iter().enumerate() {
            ctx.queue
                .write_buffer(buffer, offset as u64, bytemuck::bytes_of(&value));
            raster
                .forward(ctx, &field, &mut state, &scene.camera, &settings)
                .await?;
            side[s] = linear_functional(&state.read_render(ctx).await?, &weights);
        }
        ctx.queue
            .write_buffer(buffer, offset as u64, bytemuck::bytes_of(&base_value));
        let fd = (side[0] - side[1]) / (f64::from(values[0]) - f64::from(values[1]));
        results.push((probe.group, fd, f64::from(analytic)));
    }

    Ok(summarise(&results))
}

/// A closed, slightly bumpy UV sphere of about `faces` triangles filling the middle of a
/// `width × height` view: the benchmark scene (random colours, mid-training opacity).
pub fn sphere_scene(faces: usize, width: u32, height: u32, seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    // 2 · lon · (lat − 1) faces with lon = 2 · lat.
    let lat = (((faces as f64) / 4.0).sqrt().round() as usize).max(3);
    let lon = 2 * lat;
    let mut positions = vec![Vec3::new(0.0, 0.0, 0.5)];
    for i in 1..lat {
        let theta = std::f32::consts::PI * i as f32 / lat as f32;
        for j in 0..lon {
            let phi = std::f32::consts::TAU * j as f32 / lon as f32;
            let r = 0.5 * (1.0 + 0.04 * (3.0 * phi).sin() * (5.0 * theta).sin());
            positions.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ),
            );
        }
    }
    positions.push(Vec3::new(0.0, 0.0, -0.5));
    let ring = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
    let south = (positions.len() - 1) as u32;
    let mut tris = Vec::new();
    for j in 0..lon {
        tris.push([0, ring(1, j), ring(1, j + 1)]);
        tris.push([south, ring(lat - 1, j + 1), ring(lat - 1, j)]);
    }
    for i in 1..lat - 1 {
        for j in 0..lon {
            tris.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            tris.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    let mut field = MeshField::new(positions, tris, 4, 0.5);
    for v in 0..field.num_vertices() {
        field.set_color(v, Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()));
        let part = (v * 4 / field.num_vertices()).min(3);
        field.part_logits[v * 4 + part] = 2.0;
    }
    let camera = Camera::from_fov(
        look_at(Vec3::new(0.0, -2.2, 0.6), Vec3::ZERO, Vec3::Z),
        width,
        height,
        0.6,
        None,
    );
    Scene {
        field,
        camera,
        settings: RasterSettings {
            gamma: 0.5,
            background: Vec3::ONE,
            sh_degree: 0,
            ..RasterSettings::default()
        },
    }
}
