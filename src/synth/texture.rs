//! Procedural surface textures: wood grain, paint, brushed metal and near-textureless plastic.
//!
//! Real objects give photometric losses something to hold on to (grain, brush marks, paint speckle) — or, for
//! plastic and enamel, almost nothing, which the benchmark needs too. Every texture is tileable (the noise is
//! periodic over the image), so meshes can repeat it with UVs in metres, and is a pure function of its seed.

use std::sync::Arc;

use crate::data::RgbaImage;
use crate::object::Material;
use crate::rng::Rng;

/// Texture side in pixels: fine enough for 800² renders of a tile that covers [`TILE_METRES`].
pub(crate) const TEXTURE_SIZE: u32 = 256;

/// World size of one texture tile: shape helpers set UV = position / `TILE_METRES`.
pub(crate) const TILE_METRES: f32 = 0.5;

/// Kind of surface finish.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finish {
    /// Wood grain: dark and light growth rings, wavy, stretched along u.
    Wood,
    /// Painted surface: faint speckle and low-frequency shading.
    Paint,
    /// Brushed metal: fine streaks along u.
    Metal,
    /// Plastic or enamel: nearly uniform (the hard case for photometric cues).
    Plastic,
}

/// Periodic value noise on a `pu`×`pv` lattice, smoothly interpolated; values in [0, 1). Sampled at
/// `(u·pu·k, v·pv·k)` for whole `k`, it tiles over the unit square.
struct PeriodicNoise {
    pu: i64,
    pv: i64,
    lattice: Vec<f32>,
}

impl PeriodicNoise {
    fn new(rng: &mut Rng, pu: usize, pv: usize) -> Self {
        let lattice = (0..pu * pv).map(|_| rng.next_f32()).collect();
        PeriodicNoise {
            pu: pu as i64,
            pv: pv as i64,
            lattice,
        }
    }

    /// Noise at (u, v) in lattice units; wraps every `pu` along u and `pv` along v.
    fn at(&self, u: f32, v: f32) -> f32 {
        let (fu, fv) = (u.floor(), v.floor());
        let (tu, tv) = (smooth(u - fu), smooth(v - fv));
        let (iu, iv) = (fu as i64, fv as i64);
        let get = |x: i64, y: i64| {
            self.lattice[(y.rem_euclid(self.pv) * self.pu + x.rem_euclid(self.pu)) as usize]
        };
        let top = lerp(get(iu, iv), get(iu + 1, iv), tu);
        let bottom = lerp(get(iu, iv + 1), get(iu + 1, iv + 1), tu);
        lerp(top, bottom, tv)
    }

    /// Sum of octaves (each twice the frequency, half the amplitude), normalised to [0, 1).
    fn fractal(&self, u: f32, v: f32, octaves: u32) -> f32 {
        let (mut sum, mut amp, mut norm, mut f) = (0.0, 1.0, 0.0, 1.0);
        for _ in 0..octaves {
            sum += amp * self.at(u * f, v * f);
            norm += amp;
            amp *= 0.5;
            f *= 2.0;
        }
        sum / norm
    }
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// Linear → sRGB byte.
fn srgb_byte(linear: f32) -> u8 {
    let x = linear.clamp(0.0, 1.0);
    let s = if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// A tileable [`TEXTURE_SIZE`]² texture of `finish` around the linear colour `base`.
pub fn texture(finish: Finish, base: [f32; 3], seed: u64) -> RgbaImage {
    let mut rng = Rng::new(seed);
    let n = TEXTURE_SIZE as usize;
    // Lattice periods divide the image side so the noise tiles with the image.
    let coarse = PeriodicNoise::new(&mut rng, 4, 4);
    let speckle = PeriodicNoise::new(&mut rng, 32, 32);
    // Elongated along u: wood fibres and brush streaks.
    let streaks = PeriodicNoise::new(&mut rng, 4, 64);
    let rings = 10.0 + rng.below(8) as f32; // growth rings per tile (wood): a ring every 3 to 5 cm
    let mut pixels = Vec::with_capacity(n * n * 4);
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            let shade = match finish {
                Finish::Wood => {
                    // Rings run along u (the grain direction), warped by coarse noise.
                    let warp = coarse.fractal(u * 4.0, v * 4.0, 3);
                    let ring = (std::f32::consts::TAU * (v * rings + 1.5 * warp)).sin();
                    let fibre = streaks.at(u * 4.0, v * 64.0);
                    0.8 + 0.12 * ring + 0.12 * (fibre - 0.5)
                }
                Finish::Paint => {
                    let blotch = coarse.fractal(u * 4.0, v * 4.0, 2);
                    let dots = speckle.at(u * 32.0, v * 32.0);
                    0.92 + 0.08 * blotch + 0.05 * (dots - 0.5)
                }
                Finish::Metal => {
                    let streak = streaks.fractal(u * 4.0, v * 64.0, 2);
                    let sheen = coarse.at(u * 4.0, v * 4.0);
                    0.8 + 0.25 * (streak - 0.5) + 0.1 * sheen
                }
                Finish::Plastic => 0.97 + 0.02 * coarse.at(u * 4.0, v * 4.0),
            };
            for c in base {
                pixels.push(srgb_byte(c * shade));
            }
            pixels.push(255);
        }
    }
    RgbaImage {
        width: TEXTURE_SIZE,
        height: TEXTURE_SIZE,
        pixels,
    }
}

/// A named material whose texture carries the colour (base-colour factor white).
pub fn material(name: &str, finish: Finish, base: [f32; 3], seed: u64) -> Material {
    Material {
        name: Some(name.to_string()),
        base_color: [1.0, 1.0, 1.0, 1.0],
        texture: Some(Arc::new(texture(finish, base, seed))),
    }
}

/// An untextured named material (for small parts: knobs, handles, rubber).
pub fn plain(name: &str, base: [f32; 3]) -> Material {
    Material {
        name: Some(name.to_string()),
        base_color: [base[0], base[1], base[2], 1.0],
        texture: None,
    }
}

/// Linear base colours per finish that read as real materials (oak, walnut, white paint, steel, ...).
fn palette(finish: Finish) -> &'static [[f32; 3]] {
    match finish {
        Finish::Wood => &[
            [0.45, 0.25, 0.11],
            [0.30, 0.15, 0.06],
            [0.60, 0.40, 0.20],
            [0.20, 0.10, 0.05],
        ],
        Finish::Paint => &[
            [0.80, 0.80, 0.78],
            [0.10, 0.20, 0.45],
            [0.50, 0.08, 0.06],
            [0.15, 0.35, 0.20],
            [0.75, 0.60, 0.30],
        ],
        Finish::Metal => &[[0.55, 0.56, 0.58], [0.35, 0.36, 0.38], [0.70, 0.62, 0.45]],
        Finish::Plastic => &[
            [0.85, 0.85, 0.85],
            [0.05, 0.05, 0.05],
            [0.60, 0.10, 0.10],
            [0.10, 0.25, 0.60],
        ],
    }
}

/// A textured material of `finish` with a colour drawn from the finish's palette (slightly jittered) and a
/// texture seed drawn from `rng`.
pub(crate) fn random_material(name: &str, finish: Finish, rng: &mut Rng) -> Material {
    let base = *rng.pick(palette(finish));
    let jitter = rng.uniform(0.85, 1.15);
    let seed = rng.next_u64();
    material(name, finish, base.map(|c| (c * jitter).min(1.0)), seed)
}

/// An untextured material with a colour from `finish`'s palette (for handles, knobs, hinges).
pub(crate) fn random_plain(name: &str, finish: Finish, rng: &mut Rng) -> Material {
    plain(name, *rng.pick(palette(finish)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textures_are_deterministic_tileable_and_distinct() {
        for finish in [Finish::Wood, Finish::Paint, Finish::Metal, Finish::Plastic] {
            let a = texture(finish, [0.5, 0.3, 0.2], 7);
            assert_eq!(a, texture(finish, [0.5, 0.3, 0.2], 7));
            assert_eq!(a.pixels.len(), (TEXTURE_SIZE * TEXTURE_SIZE * 4) as usize);
            // Tileable: the last column continues into the first (no jump larger than inside the image).
            let n = TEXTURE_SIZE as usize;
            let px = |x: usize, y: usize| i32::from(a.pixels[(y * n + x) * 4]);
            let inner = (0..n).map(|y| (px(1, y) - px(0, y)).abs()).max().unwrap();
            let seam = (0..n)
                .map(|y| (px(0, y) - px(n - 1, y)).abs())
                .max()
                .unwrap();
            assert!(
                seam <= inner.max(2) * 2,
                "{finish:?}: seam {seam}, inner {inner}"
            );
        }
        let spread = |f: Finish| {
            let t = texture(f, [0.5, 0.5, 0.5], 3);
            let r: Vec<u8> = t.pixels.iter().step_by(4).copied().collect();
            r.iter().max().unwrap() - r.iter().min().unwrap()
        };
        assert!(spread(Finish::Wood) > 3 * spread(Finish::Plastic));
    }
}
