//! The consumer camera's depth map ([`super::SensorModel::Consumer`]): axial noise that grows
//! with depth squared, edges shifted sideways, dropped or mixed across the jump, random dropouts,
//! a few holes, and nothing at grazing incidence. One pass over the pixels plus the holes.
//! Every parameter is a constant below with its source (docs/method.md, "Sensor model").

use glam::Vec3;

use super::pixels::{for_each_in_disc, pick_pixel, size_scale};
use crate::data::{DepthMap, Intrinsics};
use crate::rng::Rng;

/// Axial noise σ_z at the sensor's best range (mm): the constant of Nguyen, Izadi & Lovell 2012,
/// "Modeling Kinect sensor noise for improved 3D reconstruction and tracking" (3DIMPVT),
/// σ_z(z) = 1.2 mm + 1.9 mm·(z/m − 0.4)², fitted for incidence angles below 60°.
pub const AXIAL_NOISE_MM: f32 = 1.2;

/// Growth of σ_z with depth (mm per m², same paper and equation): σ_z is 1.9 mm at 1 m and
/// 9.6 mm at 2.5 m.
pub const AXIAL_GROWTH_MM: f32 = 1.9;

/// Depth (m) at which the quadratic term of σ_z vanishes (same paper and equation).
pub const AXIAL_OFFSET_M: f32 = 0.4;

/// Incidence-angle term of σ_z (mm), same paper: + 0.1 mm/√(z/m) · θ²/(π/2 − θ)², θ the angle
/// between the surface normal and the viewing ray; 0.1 mm at 45°, 4 mm at 78°.
pub const AXIAL_ANGLE_MM: f32 = 0.1;

/// Lateral noise σ_L (pixels), same paper (σ_L = 0.8 px + 0.035 px·θ/(π/2 − θ); the angle term
/// is left out: at a depth edge the normal is unknown). Edge pixels take the depth of a
/// neighbour displaced by a Gaussian of this σ, rounded to whole pixels.
pub const LATERAL_SIGMA_PX: f32 = 0.8;

/// Smallest depth step (mm) between 4-neighbours that counts as an edge (also a measured pixel
/// beside an unmeasured one): 2 cm, an engineering choice (the "> 2 cm") that keeps
/// steep but continuous surfaces out.
pub const EDGE_JUMP_MM: f32 = 20.0;

/// A step must also exceed this many σ_z(z) of the nearer side to be an edge, so noise-sized
/// steps far away are not edges: an engineering choice (the "more than a few σ").
pub const EDGE_JUMP_SIGMAS: f32 = 4.0;

/// Chance that a pixel beside a depth edge loses its depth. Structured-light cameras leave
/// pixels beside occluding edges unmeasured, where the projector's pattern is shadowed by the
/// camera–projector baseline (the triangulation principle: Khoshelham & Elberink 2012,
/// "Accuracy and resolution of Kinect depth data for indoor mapping applications", Sensors
/// 12(2)); the rate is an engineering choice.
pub const EDGE_DROP_CHANCE: f32 = 0.25;

/// Chance that a pixel between two measured sides of a depth edge takes a depth drawn uniformly
/// between them: the "flying" or mixed pixels of time-of-flight cameras (Hansard, Lee, Choi &
/// Horaud 2012, "Time-of-Flight Cameras: Principles, Methods and Applications", Springer); the
/// rate is an engineering choice.
pub const FLYING_CHANCE: f32 = 0.25;

/// Share of pixels that lose their depth independently of everything else (speckle matching
/// failures): 1 %, an engineering choice matching the description.
pub const DROPOUT_RATE: f32 = 0.01;

/// Holes per view (inclusive range): unmeasured blobs from dark, shiny or specular patches. An
/// engineering choice matching the "a few holes per view".
pub const HOLES_PER_VIEW: (usize, usize) = (1, 4);

/// Hole radius range in pixels at the [`super::REFERENCE_WIDTH`] (800 px), scaled with
/// the image width: an engineering choice matching the "2–6 px at 800²".
pub const HOLE_RADIUS_PX: (f32, f32) = (2.0, 6.0);

/// Surfaces seen more than this far (degrees) from their normal get no depth. Nguyen et al.'s
/// angle term diverges towards 90° and their measurements stop short of it; structured light
/// cannot match its pattern on such surfaces. The 78° is an engineering choice within the
/// issue's 75–80°.
pub const GRAZING_LIMIT_DEG: f32 = 78.0;

/// σ_z (mm) of a depth `z_m` metres seen at `angle` radians from the surface normal
/// (Nguyen et al. 2012, with the angle term; the angle is held below 90°).
pub fn axial_sigma_mm(z_m: f32, angle: f32) -> f32 {
    let z = z_m.max(1e-3);
    let angle = angle.clamp(0.0, std::f32::consts::FRAC_PI_2 - 1e-2);
    let slant = angle / (std::f32::consts::FRAC_PI_2 - angle);
    AXIAL_NOISE_MM
        + AXIAL_GROWTH_MM * (z - AXIAL_OFFSET_M).powi(2)
        + AXIAL_ANGLE_MM / z.sqrt() * slant * slant
}

/// Degrades `depth` in place as the consumer camera would measure it (see the module docs);
/// `intrinsics` give the viewing rays for the incidence angle. A map whose size disagrees with
/// its pixel count is left as it is.
pub(super) fn degrade_depth(depth: &mut DepthMap, intrinsics: &Intrinsics, rng: &mut Rng) {
    let (w, h) = (depth.width as usize, depth.height as usize);
    if w == 0 || h == 0 || w.checked_mul(h) != Some(depth.millimetres.len()) {
        return;
    }
    let ideal = depth.millimetres.clone();
    let out = &mut depth.millimetres;
    let cos_limit = GRAZING_LIMIT_DEG.to_radians().cos();
    let rays = Rays::new(intrinsics);
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let edge = edge_neighbour(&ideal, w, h, x, y);
            let mm = match edge {
                Some(other) => edge_depth(&ideal, w, h, (x, y), other, rng),
                None => ideal[i],
            };
            if mm == 0 {
                out[i] = 0;
                continue;
            }
            // Edge pixels have no trustworthy normal: their angle is taken as head-on.
            let cos = if edge.is_none() {
                rays.incidence_cos(&ideal, w, h, x, y)
            } else {
                1.0
            };
            if cos < cos_limit || rng.chance(DROPOUT_RATE) {
                out[i] = 0;
                continue;
            }
            let sigma = axial_sigma_mm(f32::from(mm) / 1000.0, cos.clamp(-1.0, 1.0).acos());
            out[i] = (f32::from(mm) + sigma * rng.normal())
                .round()
                .clamp(1.0, 65535.0) as u16;
        }
    }
    punch_holes(out, w, h, rng);
}

/// The 4-neighbour across the largest depth edge at `(x, y)` (a measured pixel beside an
/// unmeasured one counts as the largest), `None` when no neighbour is across an edge.
fn edge_neighbour(ideal: &[u16], w: usize, h: usize, x: usize, y: usize) -> Option<usize> {
    let here = ideal[y * w + x];
    let mut best: Option<(usize, f32)> = None;
    let neighbours = [
        (x > 0).then(|| y * w + x - 1),
        (x + 1 < w).then(|| y * w + x + 1),
        (y > 0).then(|| (y - 1) * w + x),
        (y + 1 < h).then(|| (y + 1) * w + x),
    ];
    for n in neighbours.into_iter().flatten() {
        let there = ideal[n];
        let step = match (here, there) {
            (0, 0) => continue,
            (0, _) | (_, 0) => f32::INFINITY,
            _ => {
                let step = f32::from(here.abs_diff(there));
                // The σ test only where the 2 cm one passes: most steps are far smaller.
                let near_m = f32::from(here.min(there)) / 1000.0;
                if step <= EDGE_JUMP_MM || step <= EDGE_JUMP_SIGMAS * axial_sigma_mm(near_m, 0.0) {
                    continue;
                }
                step
            }
        };
        if best.is_none_or(|(_, s)| step > s) {
            best = Some((n, step));
        }
    }
    best.map(|(n, _)| n)
}

/// The depth an edge pixel reads: a neighbour's at the lateral error, then dropped, or mixed
/// between the two sides of the edge (`other` is the pixel across it).
fn edge_depth(
    ideal: &[u16],
    w: usize,
    h: usize,
    (x, y): (usize, usize),
    other: usize,
    rng: &mut Rng,
) -> u16 {
    let shift = |rng: &mut Rng| (LATERAL_SIGMA_PX * rng.normal()).round().clamp(-2.0, 2.0) as i64;
    let sx = (x as i64 + shift(rng)).clamp(0, w as i64 - 1) as usize;
    let sy = (y as i64 + shift(rng)).clamp(0, h as i64 - 1) as usize;
    let shifted = ideal[sy * w + sx];
    if rng.chance(EDGE_DROP_CHANCE) {
        return 0;
    }
    let (here, there) = (ideal[y * w + x], ideal[other]);
    if here != 0 && there != 0 && rng.chance(FLYING_CHANCE) {
        let t = rng.next_f32();
        let mixed = f32::from(here) + t * (f32::from(there) - f32::from(here));
        return mixed.round().clamp(1.0, 65535.0) as u16;
    }
    shifted
}

/// Clears a few discs of measured pixels (see [`HOLES_PER_VIEW`], [`HOLE_RADIUS_PX`]).
fn punch_holes(depth: &mut [u16], w: usize, h: usize, rng: &mut Rng) {
    let scale = size_scale(w as u32);
    let count = rng.int_in(HOLES_PER_VIEW.0, HOLES_PER_VIEW.1);
    for _ in 0..count {
        let radius = scale * rng.uniform(HOLE_RADIUS_PX.0, HOLE_RADIUS_PX.1);
        let Some(centre) = pick_pixel(w, h, rng, |i| depth[i] != 0) else {
            return;
        };
        for_each_in_disc(w, h, centre, radius, |i| depth[i] = 0);
    }
}

/// Back-projection of pixels through pinhole intrinsics, for the incidence angle.
struct Rays {
    inverse_fx: f32,
    inverse_fy: f32,
    cx: f32,
    cy: f32,
}

impl Rays {
    fn new(k: &Intrinsics) -> Self {
        // Non-finite or zero focal lengths fall back to a 90° view: only angles come from it.
        let focal = |f: f32, size: u32| {
            if f.is_finite() && f.abs() > 1e-6 {
                f
            } else {
                0.5 * size.max(1) as f32
            }
        };
        let centre = |c: f32, size: u32| if c.is_finite() { c } else { 0.5 * size as f32 };
        Rays {
            inverse_fx: 1.0 / focal(k.fx, k.width),
            inverse_fy: 1.0 / focal(k.fy, k.height),
            cx: centre(k.cx, k.width),
            cy: centre(k.cy, k.height),
        }
    }

    /// The camera-space point of pixel `(x, y)` at z-depth `mm`.
    fn point(&self, x: usize, y: usize, mm: u16) -> Vec3 {
        let z = f32::from(mm);
        Vec3::new(
            (x as f32 + 0.5 - self.cx) * self.inverse_fx * z,
            (self.cy - y as f32 - 0.5) * self.inverse_fy * z,
            -z,
        )
    }

    /// |cos| of the angle between the viewing ray of pixel `(x, y)` and the surface normal
    /// estimated from its neighbours' depths; 1 (head-on) when no normal can be estimated.
    fn incidence_cos(&self, ideal: &[u16], w: usize, h: usize, x: usize, y: usize) -> f32 {
        let at = |x: usize, y: usize| self.point(x, y, ideal[y * w + x]);
        let (left, right) = (x.saturating_sub(1), (x + 1).min(w - 1));
        let (up, down) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let normal = (at(right, y) - at(left, y)).cross(at(x, down) - at(x, up));
        let ray = at(x, y);
        let norms = normal.length() * ray.length();
        if !(norms > 0.0 && norms.is_finite()) {
            return 1.0;
        }
        (normal.dot(ray) / norms).abs()
    }
}
