//! Collision shapes a simulator can use: each part of a twin as a few convex pieces, cut so that
//! no movable part's pieces overlap another part's anywhere along its joint's range.
//!
//! - A simulator takes the convex hull of a mesh collision, and one hull per part swallows a
//!   cabinet's drawers: the body's hull fills the cavities they slide in. So each part's surface
//!   is split into convex pieces by V-HACD (parry3d): voxelise, then cut the voxels along the
//!   planes that most reduce concavity. Each piece is the hull of the part's own surface points in
//!   its voxels (the surface sampled at half the voxel size), not of the voxels, so it does not
//!   grow by half a voxel.
//! - The pieces of a thin part (a door is a sheet) are flat; each is thickened to
//!   [`MIN_THICKNESS`] so that it has a volume to collide with.
//! - A fitted surface is a few millimetres off and its unseen insides are guesses, so pieces of
//!   different parts can overlap where the real parts only touch. Each movable part is swept over
//!   its joint's range ([`CollisionOptions::sweep_samples`] poses); wherever one of its pieces
//!   overlaps a piece of the base or of another part at rest, the pair is separated along its
//!   axis of least overlap (face normals of either hull: the separating-axis test), by cutting
//!   whichever of the two loses less volume, and leaving [`CollisionOptions::clearance`].

use std::collections::HashMap;

use glam::{Affine3A, Vec3};
use parry3d::transformation::try_convex_hull;
use parry3d::transformation::vhacd::{VHACD, VHACDParameters};
use parry3d::transformation::voxelization::FillMode;

use crate::data::{GtJoint, JointKind as GtKind, TriMesh};

/// Thinnest a convex piece may be (m): flat pieces are thickened to this.
pub const MIN_THICKNESS: f32 = 2e-3;
/// Most points sampled on one triangle's side (bounds the work on a huge, coarse triangle).
const MAX_TRIANGLE_STEPS: usize = 64;
/// Farthest a point of a moving part goes between two sampled poses (m).
const SWEEP_STEP: f32 = 2e-3;
/// Most poses sampled along one joint.
const MAX_SWEEP_SAMPLES: usize = 400;
/// Cuts tried on one pair of pieces at one pose before giving up on it.
const MAX_CUTS_PER_PAIR: usize = 8;

/// How the collision shapes are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollisionOptions {
    /// V-HACD's voxels along a part's longest side.
    pub resolution: u32,
    /// V-HACD's concavity threshold (fraction of the part's volume).
    pub concavity: f32,
    /// Most convex pieces per part.
    pub max_pieces: u32,
    /// Fewest poses across each movable part's joint range at which overlaps are cleared (ends
    /// included); more where a point would otherwise move more than 2 mm between two.
    pub sweep_samples: usize,
    /// Gap left between two pieces cut apart (m).
    pub clearance: f32,
}

impl Default for CollisionOptions {
    fn default() -> Self {
        CollisionOptions {
            resolution: 64,
            concavity: 0.01,
            max_pieces: 24,
            sweep_samples: 17,
            clearance: 5e-3,
        }
    }
}

/// One convex piece: its hull's vertices and outward-wound triangles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ConvexPiece {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl ConvexPiece {
    /// The convex hull of `points`, thickened to [`MIN_THICKNESS`] when flat; `None` without
    /// finite points.
    pub fn hull(points: &[Vec3]) -> Option<ConvexPiece> {
        let points: Vec<Vec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
        let first = *points.first()?;
        let (normal, thickness) = thinnest_axis(&points);
        let mut cloud = points.clone();
        if thickness < MIN_THICKNESS {
            // A sheet, a stick or a point: give it volume along its thinnest axis (and, for a
            // stick or a point, along the others too).
            let axes = orthonormal_basis(normal);
            let half = 0.5 * MIN_THICKNESS;
            cloud = points
                .iter()
                .flat_map(|&p| axes.iter().flat_map(move |&a| [p + a * half, p - a * half]))
                .collect();
            cloud.push(first);
        }
        let converted: Vec<parry3d::math::Vector> = cloud
            .iter()
            .map(|p| parry3d::math::Vector::new(p.x, p.y, p.z))
            .collect();
        let (vertices, triangles) = try_convex_hull(&converted).ok()?;
        let piece = ConvexPiece {
            positions: vertices.iter().map(|v| Vec3::new(v.x, v.y, v.z)).collect(),
            triangles,
        };
        (piece.triangles.len() >= 4 && piece.volume() > 0.0).then_some(piece)
    }

    /// Enclosed volume (m³).
    pub fn volume(&self) -> f32 {
        let p = &self.positions;
        let six: f32 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                a.dot(b.cross(c))
            })
            .sum();
        six.abs() / 6.0
    }

    /// The piece moved by `t`.
    pub fn transformed(&self, t: &Affine3A) -> ConvexPiece {
        ConvexPiece {
            positions: self
                .positions
                .iter()
                .map(|&p| t.transform_point3(p))
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The part of the piece where `n·x ≤ c`; `None` when too little is left to be a solid.
    pub fn clipped(&self, n: Vec3, c: f32) -> Option<ConvexPiece> {
        let side = |p: Vec3| n.dot(p) - c;
        let mut kept: Vec<Vec3> = self
            .positions
            .iter()
            .copied()
            .filter(|&p| side(p) <= 0.0)
            .collect();
        for t in &self.triangles {
            for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (a, b) = (self.positions[i as usize], self.positions[j as usize]);
                let (sa, sb) = (side(a), side(b));
                if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
                    kept.push(a + (b - a) * (sa / (sa - sb)));
                }
            }
        }
        let clipped = ConvexPiece::hull(&kept)?;
        (clipped.thickness() >= 0.5 * MIN_THICKNESS).then_some(clipped)
    }

    /// Extent along the thinnest principal axis of the vertices (m).
    fn thickness(&self) -> f32 {
        let (n, _) = thinnest_axis(&self.positions);
        let (lo, hi) = self.interval(n);
        hi - lo
    }

    /// Unit outward normals of the hull's faces.
    fn normals(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.triangles.iter().filter_map(|t| {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            (n.length_squared() > 0.0).then(|| n.normalize())
        })
    }

    /// The smallest and largest of `n·x` over the vertices.
    fn interval(&self, n: Vec3) -> (f32, f32) {
        self.positions
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &p| {
                let d = n.dot(p);
                (lo.min(d), hi.max(d))
            })
    }

    /// Bounds of the vertices.
    fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }
}

/// How deep two convex pieces overlap and along which axis, by the separating-axis test over
/// both hulls' face normals: `None` when some axis separates them by at least `gap`. The axis
/// `n` is oriented so that moving `a` by `−depth·n` (or `b` by `+depth·n`) leaves `gap` between
/// them.
fn overlap(a: &ConvexPiece, b: &ConvexPiece, gap: f32) -> Option<(Vec3, f32)> {
    let (alo, ahi) = a.bounds();
    let (blo, bhi) = b.bounds();
    if (alo - gap).cmpgt(bhi).any() || (blo - gap).cmpgt(ahi).any() {
        return None;
    }
    let mut best: Option<(Vec3, f32)> = None;
    for n in a.normals().chain(b.normals()) {
        let (a0, a1) = a.interval(n);
        let (b0, b1) = b.interval(n);
        // Push a down (a below b) or up (a above b) along n.
        for (axis, depth) in [(n, a1 - b0 + gap), (-n, b1 - a0 + gap)] {
            if depth <= 0.0 {
                return None;
            }
            if best.is_none_or(|(_, d)| depth < d) {
                best = Some((axis, depth));
            }
        }
    }
    best
}

/// The decomposition of one part's surface (world frame) into convex pieces.
pub fn convex_pieces(mesh: &TriMesh, opts: &CollisionOptions) -> Vec<ConvexPiece> {
    let n = mesh.positions.len();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .copied()
        .filter(|t| {
            t.iter()
                .all(|&i| (i as usize) < n && mesh.positions[i as usize].is_finite())
        })
        .collect();
    if triangles.is_empty() {
        return Vec::new();
    }
    let points: Vec<parry3d::math::Vector> = mesh
        .positions
        .iter()
        .map(|p| parry3d::math::Vector::new(p.x, p.y, p.z))
        .collect();
    let params = VHACDParameters {
        resolution: opts.resolution.max(8),
        concavity: opts.concavity,
        max_convex_hulls: opts.max_pieces.max(1),
        fill_mode: FillMode::FloodFill {
            detect_cavities: false,
        },
        ..VHACDParameters::default()
    };
    let decomposition = VHACD::decompose(&params, &points, &triangles, false);
    let parts = decomposition.voxel_parts();
    let Some(first) = parts.first() else {
        return ConvexPiece::hull(&mesh.positions).into_iter().collect();
    };
    let (origin, scale) = (first.origin, first.scale);
    let origin = Vec3::new(origin.x, origin.y, origin.z);
    let mut owner: HashMap<[i32; 3], usize> = HashMap::new();
    for (k, part) in parts.iter().enumerate() {
        for v in part.voxels() {
            owner.insert([v.coords.x, v.coords.y, v.coords.z], k);
        }
    }
    let mut clouds: Vec<Vec<Vec3>> = vec![Vec::new(); parts.len()];
    let cell = |p: Vec3| ((p - origin) / scale).round().as_ivec3().to_array();
    for t in &triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        for p in triangle_samples(a, b, c, 0.5 * scale) {
            if let Some(&k) = owner.get(&cell(p)) {
                clouds[k].push(p);
            }
        }
    }
    parts
        .iter()
        .zip(&mut clouds)
        .filter_map(|(part, cloud)| {
            if cloud.is_empty() {
                // Inside voxels only (a closed part's core): the voxels' centres stand for it.
                cloud.extend(part.voxels().iter().map(|v| {
                    let q = part.get_voxel_point(v);
                    Vec3::new(q.x, q.y, q.z)
                }));
            }
            ConvexPiece::hull(cloud)
        })
        .collect()
}

/// Points on triangle `abc` no further than about `step` apart (its corners included).
fn triangle_samples(a: Vec3, b: Vec3, c: Vec3, step: f32) -> Vec<Vec3> {
    let longest = (b - a).length().max((c - b).length()).max((a - c).length());
    let steps = ((longest / step).ceil() as usize).clamp(1, MAX_TRIANGLE_STEPS);
    let mut out = Vec::with_capacity((steps + 1) * (steps + 2) / 2);
    for i in 0..=steps {
        for j in 0..=steps - i {
            let (u, v) = (i as f32 / steps as f32, j as f32 / steps as f32);
            out.push(a + (b - a) * u + (c - a) * v);
        }
    }
    out
}

/// A movable part's joint: where its pieces go at a joint value, and the range of values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// The moving part's index (1 ..= K; 0 is the base).
    pub part: usize,
    pub joint: GtJoint,
}

/// Cuts the pieces of `parts` (world frame, start state; base first) so that no moving part's
/// piece overlaps another part's piece at rest, at any of the sampled joint values of its
/// `sweeps`; returns how many cuts were made. Pieces cut down to nothing are dropped.
pub fn clear_overlaps(
    parts: &mut [Vec<ConvexPiece>],
    sweeps: &[Sweep],
    opts: &CollisionOptions,
) -> usize {
    let mut cuts = 0;
    for sweep in sweeps {
        let k = sweep.part;
        if k >= parts.len() {
            continue;
        }
        let motion = sweep.joint.urdf_motion();
        // Sample finely enough that no point moves more than SWEEP_STEP between poses: a thin
        // obstacle could otherwise sit between two of them.
        let reach = match sweep.joint.kind {
            GtKind::Prismatic => motion.abs(),
            GtKind::Revolute => {
                let (o, d) = (sweep.joint.origin, sweep.joint.unit_direction());
                let radius = parts[k]
                    .iter()
                    .flat_map(|p| &p.positions)
                    .map(|&p| (p - o).reject_from_normalized(d).length())
                    .fold(0.0, f32::max);
                motion.abs() * radius
            }
        };
        let fine = (reach / SWEEP_STEP).ceil() as usize + 1;
        let samples = opts.sweep_samples.max(2).max(fine.min(MAX_SWEEP_SAMPLES));
        for s in 0..samples {
            let value = motion * s as f32 / (samples - 1) as f32;
            let pose = sweep.joint.pose_at(value);
            let inverse = pose.inverse();
            for other in (0..parts.len()).filter(|&o| o != k) {
                cuts += separate(parts, k, other, &pose, &inverse, opts.clearance);
            }
        }
    }
    cuts
}

/// Separates every piece of part `k` posed by `pose` from every piece of part `other` at rest.
fn separate(
    parts: &mut [Vec<ConvexPiece>],
    k: usize,
    other: usize,
    pose: &Affine3A,
    inverse: &Affine3A,
    gap: f32,
) -> usize {
    let mut cuts = 0;
    let mut i = 0;
    while i < parts[k].len() {
        let mut j = 0;
        let mut moving = parts[k][i].transformed(pose);
        let mut removed = false;
        while j < parts[other].len() && !removed {
            let mut tries = 0;
            while let Some((n, _)) = overlap(&moving, &parts[other][j], gap) {
                tries += 1;
                cuts += 1;
                // Either cut the moving piece back along −n, or the other one along +n.
                let (_, a_top) = moving.interval(n);
                let (b_bottom, _) = parts[other][j].interval(n);
                let cut_moving = moving.clipped(n, b_bottom - gap);
                let cut_other = parts[other][j].clipped(-n, -(a_top + gap));
                let loss = |before: &ConvexPiece, after: &Option<ConvexPiece>| {
                    before.volume() - after.as_ref().map_or(0.0, ConvexPiece::volume)
                };
                if loss(&moving, &cut_moving) <= loss(&parts[other][j], &cut_other) {
                    match cut_moving {
                        Some(piece) => moving = piece,
                        None => {
                            parts[k].remove(i);
                            removed = true;
                            break;
                        }
                    }
                } else if let Some(piece) = cut_other {
                    parts[other][j] = piece;
                } else {
                    parts[other].remove(j);
                    break;
                }
                if tries >= MAX_CUTS_PER_PAIR {
                    break;
                }
            }
            if !removed && j < parts[other].len() {
                j += 1;
            }
        }
        if !removed {
            parts[k][i] = moving.transformed(inverse);
            i += 1;
        }
    }
    cuts
}

/// Unit direction of least spread of `points` and the spread along it (max − min, m).
fn thinnest_axis(points: &[Vec3]) -> (Vec3, f32) {
    let Some(frame) = crate::articulation::init::principal_frame(points) else {
        return (Vec3::Z, 0.0);
    };
    let n = frame.axes.z_axis.as_vec3().normalize_or(Vec3::Z);
    let (lo, hi) = points
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(n.dot(p)), hi.max(n.dot(p)))
        });
    (n, hi - lo)
}

/// `n` and two unit vectors perpendicular to it and to each other.
fn orthonormal_basis(n: Vec3) -> [Vec3; 3] {
    let (u, v) = n.any_orthonormal_pair();
    [n, u, v]
}

/// The collision pieces of every part (`meshes`, world frame, start state; base first, part k
/// moved by `joints[k − 1]`), cleared along every joint.
pub fn part_collisions(
    meshes: &[&TriMesh],
    joints: &[GtJoint],
    opts: &CollisionOptions,
) -> Vec<Vec<ConvexPiece>> {
    let mut parts = crate::data::parallel::map(meshes, |m| convex_pieces(m, opts));
    let sweeps: Vec<Sweep> = joints
        .iter()
        .enumerate()
        .map(|(i, &joint)| Sweep { part: i + 1, joint })
        .collect();
    clear_overlaps(&mut parts, &sweeps, opts);
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::fixture::box_mesh;

    /// `meshes` as one mesh.
    fn union(meshes: &[TriMesh]) -> TriMesh {
        let mut out = TriMesh::default();
        for m in meshes {
            let base = out.positions.len() as u32;
            out.positions.extend(&m.positions);
            out.triangles
                .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        out
    }

    #[test]
    fn hulls_clip_and_thicken() {
        let cube = ConvexPiece::hull(&box_mesh(Vec3::ZERO, Vec3::ONE).positions).unwrap();
        assert!((cube.volume() - 1.0).abs() < 1e-5);
        let half = cube.clipped(Vec3::X, 0.25).unwrap();
        assert!((half.volume() - 0.25).abs() < 1e-5, "{}", half.volume());
        assert!(cube.clipped(Vec3::X, -0.1).is_none());
        // A unit square has no volume: it gets MIN_THICKNESS of it.
        let square = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let sheet = ConvexPiece::hull(&square).unwrap();
        let (lo, hi) = sheet.bounds();
        assert!((hi.z - lo.z - MIN_THICKNESS).abs() < 1e-6, "{lo} {hi}");
        assert!(ConvexPiece::hull(&[Vec3::NAN]).is_none());
    }

    #[test]
    fn overlap_is_the_separating_axis_depth() {
        let a = ConvexPiece::hull(&box_mesh(Vec3::ZERO, Vec3::ONE).positions).unwrap();
        let b = a.transformed(&Affine3A::from_translation(Vec3::new(0.9, 0.2, 0.0)));
        let (n, depth) = overlap(&a, &b, 0.0).unwrap();
        assert!(
            n.abs_diff_eq(Vec3::X, 1e-6) && (depth - 0.1).abs() < 1e-5,
            "{n} {depth}"
        );
        assert!(overlap(&a, &b, 0.0).is_some());
        let apart = a.transformed(&Affine3A::from_translation(Vec3::new(1.01, 0.0, 0.0)));
        assert!(overlap(&a, &apart, 0.0).is_none());
        assert!(overlap(&a, &apart, 0.02).is_some());
    }

    /// A cabinet (five walls, open at +x) with a drawer that slides out along +x: the cabinet's
    /// pieces leave the cavity open, and along the whole slide no drawer piece comes within the
    /// clearance of a cabinet piece, where one hull per part would overlap by the drawer's size.
    #[test]
    fn a_drawer_slides_out_of_its_cabinet_without_overlap() {
        let t = 0.02;
        let cabinet = union(&[
            box_mesh(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 0.5, t)),
            box_mesh(Vec3::new(0.0, 0.0, 0.5 - t), Vec3::new(0.5, 0.5, 0.5)),
            box_mesh(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, t, 0.5)),
            box_mesh(Vec3::new(0.0, 0.5 - t, 0.0), Vec3::new(0.5, 0.5, 0.5)),
            box_mesh(Vec3::new(0.0, 0.0, 0.0), Vec3::new(t, 0.5, 0.5)),
        ]);
        // The drawer fills the cavity a little too well: 1 mm into the walls, as a fit might.
        let drawer = box_mesh(
            Vec3::new(t, t - 1e-3, t - 1e-3),
            Vec3::new(0.5, 0.5 - t + 1e-3, 0.3),
        );
        let opts = CollisionOptions::default();
        let mut parts = vec![
            convex_pieces(&cabinet, &opts),
            convex_pieces(&drawer, &opts),
        ];
        assert!(parts[0].len() >= 5, "{} cabinet pieces", parts[0].len());
        let joint = GtJoint {
            kind: GtKind::Prismatic,
            origin: Vec3::ZERO,
            direction: Vec3::X,
            start: 0.0,
            end: 0.3,
        };
        let cuts = clear_overlaps(&mut parts, &[Sweep { part: 1, joint }], &opts);
        assert!(cuts > 0);
        let drawer_volume: f32 = parts[1].iter().map(ConvexPiece::volume).sum();
        assert!(drawer_volume > 0.5 * 0.46 * 0.46 * 0.28, "{drawer_volume}");
        for s in 0..=30 {
            let pose = Affine3A::from_translation(Vec3::X * 0.01 * s as f32);
            for a in &parts[1] {
                let moved = a.transformed(&pose);
                for b in &parts[0] {
                    assert!(
                        overlap(&moved, b, 0.5 * opts.clearance).is_none(),
                        "at {s} cm"
                    );
                }
            }
        }
    }
}
