//! Initialisation of a state's mesh field from its RGB-D frames (no structure-from-motion: the
//! depth maps give the surface). Every valid foreground pixel is back-projected; the samples are
//! thinned on a voxel grid per part (averaging position, colour and normal); each surviving
//! sample seeds one small triangle in its tangent plane, facing the camera that saw it, coloured
//! from the image, half transparent, with part logits from the semantic map.

use glam::{Vec2, Vec3};
use serde::Serialize;

use crate::data::{Camera, Frame};
use crate::mesh::topology::groups_in_order;
use crate::raster::MeshField;
use crate::rng::Rng;

/// How the initial triangles are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InitOptions {
    /// Sample spacing in pixels at the median depth: the voxel size of the thinning.
    pub spacing_pixels: f32,
    /// Seed triangles' circumradius as a fraction of the spacing.
    pub triangle_radius: f32,
    /// At most this many seed triangles (the spacing grows until they fit).
    pub max_triangles: usize,
    /// Logit given to the part the semantic map names (the others get 0).
    pub part_logit: f32,
    /// Initial opacity logit (0 = σ 0.5).
    pub opacity_logit: f32,
    pub seed: u64,
}

impl Default for InitOptions {
    fn default() -> Self {
        Self {
            spacing_pixels: 2.0,
            triangle_radius: 1.1,
            max_triangles: 20_000,
            part_logit: 4.0,
            opacity_logit: 0.0,
            seed: 7,
        }
    }
}

/// One back-projected pixel.
#[derive(Debug, Clone, Copy)]
struct Sample {
    position: Vec3,
    normal: Vec3,
    color: Vec3,
    part: u32,
}

/// World point of pixel (x, y) if its depth is valid.
fn back_project(camera: &Camera, frame: &Frame, x: i64, y: i64) -> Option<Vec3> {
    let depth = frame.depth.as_ref()?;
    if x < 0 || y < 0 || x >= i64::from(depth.width) || y >= i64::from(depth.height) {
        return None;
    }
    let mm = depth.millimetres[(y as u32 * depth.width + x as u32) as usize];
    (mm > 0).then(|| {
        camera.unproject(
            Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
            f32::from(mm) / 1000.0,
        )
    })
}

/// Back-projects every foreground pixel with depth; normals from central differences of the
/// depth map, falling back to the viewing direction across depth edges.
fn frame_samples(frame: &Frame, num_parts: usize, out: &mut Vec<Sample>) {
    let (Some(depth), camera) = (frame.depth.as_ref(), frame.camera) else {
        return;
    };
    let (w, h) = (depth.width, depth.height);
    if frame.rgba.width != w || frame.rgba.height != h {
        return;
    }
    let eye = camera.position();
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let i = (y as u32 * w + x as u32) as usize;
            if frame.rgba.pixels[4 * i + 3] < 128 {
                continue;
            }
            let Some(p) = back_project(&camera, frame, x, y) else {
                continue;
            };
            let part = match &frame.parts {
                Some(map) if map.width == w && map.height == h => {
                    let id = map.ids[i];
                    if id < 0 || id as usize >= num_parts {
                        continue;
                    }
                    id as u32
                }
                _ => 0,
            };
            let to_eye = (eye - p).normalize_or_zero();
            let near = |q: Option<Vec3>| q.filter(|q| q.distance(p) < 0.05 * p.distance(eye));
            let normal = match (
                near(back_project(&camera, frame, x + 1, y)),
                near(back_project(&camera, frame, x - 1, y)),
                near(back_project(&camera, frame, x, y + 1)),
                near(back_project(&camera, frame, x, y - 1)),
            ) {
                (Some(r), Some(l), Some(d), Some(u)) => {
                    let n = (r - l).cross(d - u).normalize_or_zero();
                    if n.dot(to_eye) < 0.0 { -n } else { n }
                }
                _ => to_eye,
            };
            let px = &frame.rgba.pixels[4 * i..4 * i + 3];
            let color = Vec3::new(f32::from(px[0]), f32::from(px[1]), f32::from(px[2])) / 255.0;
            out.push(Sample {
                position: p,
                normal: if normal == Vec3::ZERO { to_eye } else { normal },
                color,
                part,
            });
        }
    }
}

/// Averages the samples per (voxel, part).
fn thin(samples: &[Sample], cell: f32) -> Vec<Sample> {
    let groups = groups_in_order(
        samples
            .iter()
            .map(|s| ((s.position / cell).floor().as_ivec3().to_array(), s.part)),
    );
    groups
        .iter()
        .map(|group| {
            let members = || group.iter().map(|&i| &samples[i as usize]);
            let n = group.len() as f32;
            let sum = |f: fn(&Sample) -> Vec3| members().map(f).sum::<Vec3>();
            Sample {
                position: sum(|s| s.position) / n,
                normal: sum(|s| s.normal).normalize_or(Vec3::Z),
                color: sum(|s| s.color) / n,
                // Every member shares the voxel's part (it is in the key).
                part: samples[group[0] as usize].part,
            }
        })
        .collect()
}

/// Why [`initial_field`] has nothing to start from: no frame has a usable depth map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "no frame has foreground pixels with valid depth: the reconstruction starts from the depth maps"
)]
pub(crate) struct NoDepthSamples;

/// The initial mesh field of one state (see the module docs). Errors when no frame has a usable
/// depth map.
pub(crate) fn initial_field(
    frames: &[Frame],
    num_parts: usize,
    options: &InitOptions,
) -> Result<MeshField, NoDepthSamples> {
    let mut samples = Vec::new();
    for frame in frames {
        frame_samples(frame, num_parts, &mut samples);
    }
    if samples.is_empty() {
        return Err(NoDepthSamples);
    }
    // Pixel footprint at the median depth of the first view sets the voxel size.
    let first = frames.iter().find(|f| f.depth.is_some()).map(|f| f.camera);
    let mut depths: Vec<f32> = match first {
        Some(c) => samples
            .iter()
            .map(|s| s.position.distance(c.position()))
            .collect(),
        None => vec![1.0],
    };
    depths.sort_by(f32::total_cmp);
    let median = depths[depths.len() / 2];
    let fx = first.map_or(1.0, |c| c.intrinsics.fx).max(1e-6);
    let mut cell = options.spacing_pixels.max(0.1) * median / fx;
    let mut seeds = thin(&samples, cell);
    while seeds.len() > options.max_triangles.max(1) {
        cell *= (seeds.len() as f32 / options.max_triangles.max(1) as f32)
            .sqrt()
            .max(1.05);
        seeds = thin(&samples, cell);
    }

    let mut rng = Rng::new(options.seed);
    let radius = options.triangle_radius * cell;
    let mut positions = Vec::with_capacity(3 * seeds.len());
    let mut faces = Vec::with_capacity(seeds.len());
    for s in &seeds {
        // A random in-plane rotation, so the soup has no preferred edge direction.
        let (t, b) = s.normal.any_orthonormal_pair();
        let phase = rng.uniform(0.0, std::f32::consts::TAU);
        let base = positions.len() as u32;
        // Counter-clockwise about the normal, so the face normal is the sample's.
        for k in 0..3 {
            let a = phase + k as f32 * std::f32::consts::TAU / 3.0;
            positions.push(s.position + radius * (a.cos() * t + a.sin() * b));
        }
        faces.push([base, base + 1, base + 2]);
    }
    let mut field = MeshField::new(positions, faces, num_parts, options.opacity_logit);
    for (i, s) in seeds.iter().enumerate() {
        for k in 0..3 {
            let v = 3 * i + k;
            field.set_color(v, s.color);
            field.part_logits[v * num_parts + s.part as usize] = options.part_logit;
        }
    }
    Ok(field)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::fixture;

    #[test]
    fn seeds_lie_on_the_surface_and_face_the_cameras() {
        let dataset = fixture::small_dataset(fixture::FixtureParams::default());
        let frames = &dataset.views[0].frames;
        let field = initial_field(frames, dataset.num_parts, &InitOptions::default()).unwrap();
        field.validate().unwrap();
        assert!(field.faces.len() > 50, "{} seeds", field.faces.len());
        // Every seed's normal points at the side some camera is on.
        let normals = crate::mesh::topology::vertex_normals(&field.positions, &field.faces);
        for f in &field.faces {
            let c = (field.positions[f[0] as usize] + field.positions[f[1] as usize]) / 2.0;
            let seen = frames
                .iter()
                .any(|fr| normals[f[0] as usize].dot(fr.camera.position() - c) > 0.0);
            assert!(seen);
        }
        // Every part the semantic maps show gets seeds.
        let parts = crate::mesh::harden_parts(&field);
        for k in 0..dataset.num_parts as u32 {
            assert!(parts.contains(&k), "part {k} has no seeds");
        }
    }

    #[test]
    fn no_depth_is_a_clear_error() {
        let mut dataset = fixture::small_dataset(fixture::FixtureParams::default());
        for f in &mut dataset.views[0].frames {
            f.depth = None;
        }
        let err = initial_field(&dataset.views[0].frames, 2, &InitOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("depth"), "{err}");
    }
}
