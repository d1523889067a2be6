//! Vertex-wise motion consistency (paper §3.2, "Vertex-wise Motion Consistency"), on the CPU,
//! one direction at a time.
//!
//! Every vertex of a movable part in the source state is carried by its part's rigid motion,
//! x̂ᵢ = A_p xᵢ + b_p, and compared with the target state's surface of the *same* part at the
//! closest point: the target's colours and opacities, interpolated there with the closest point's
//! barycentric weights β, should match the source vertex's own. Matches farther than a threshold
//! are ignored (the validity indicator ηᵢ of the paper):
//!
//! L = 1/|V| Σᵢ ηᵢ [λ_c ‖cᵢ − Σⱼ βᵢⱼ cⱼ‖² + λ_σ (σᵢ − Σⱼ βᵢⱼ σⱼ)²].
//!
//! Attributes are constants here, so the loss reaches the motion only through where x̂ᵢ lands on
//! the target triangle, i.e. through β(x̂ᵢ). The per-vertex gradients gᵢ = ∂L/∂x̂ᵢ are reduced to
//! [`PartSums`] (Σ gᵢ, Σ gᵢ xᵢᵀ with xᵢ before the motion), which is all the motion parameters
//! need. The forward direction (t₁ → t₂) passes the forward motions; the backward direction
//! swaps the surfaces and passes the analytic inverses (Aᵀ, −Aᵀ b).

use glam::{DMat3, DVec3, Vec3};

pub use self::error::{MotionLossError, SurfaceError};
use super::PartSums;
use crate::mesh::closest::TriangleBvh;
use crate::raster::MeshField;

/// One articulation state's mesh as the vertex-wise term sees it: per-vertex position, colour,
/// opacity and hardened part label, with one closest-point tree per part.
#[derive(Debug, Clone)]
pub struct StateSurface {
    positions: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    parts: Vec<u32>,
    colors: Vec<Vec3>,
    opacity: Vec<f32>,
    num_parts: usize,
    /// Per part: indices into `faces` of its faces, in the order its tree names them.
    part_faces: Vec<Vec<u32>>,
    /// Per part: the tree over exactly those faces.
    part_trees: Vec<TriangleBvh>,
    /// Faces whose vertices carry different labels (left out of every tree).
    cross_part_faces: usize,
}

impl StateSurface {
    /// A state surface from per-vertex arrays (`parts` in 0..`num_parts`, 0 the static base;
    /// `colors` RGB; `opacity` in [0, 1]). A face belongs to the part its three vertices share;
    /// faces whose vertices disagree are left out of the search (part-aware remeshing leaves
    /// none) and counted in [`Self::cross_part_faces`].
    ///
    /// Errors (never panics) on mismatched lengths, out-of-range indices or labels, non-finite
    /// positions or colours, and opacities outside [0, 1].
    pub fn new(
        positions: Vec<Vec3>,
        faces: Vec<[u32; 3]>,
        parts: Vec<u32>,
        colors: Vec<Vec3>,
        opacity: Vec<f32>,
        num_parts: usize,
    ) -> Result<Self, SurfaceError> {
        let n = positions.len();
        if num_parts == 0 {
            return Err(SurfaceError::NoParts);
        }
        if u32::try_from(n).is_err() {
            return Err(SurfaceError::TooManyVertices(n));
        }
        for (what, len) in [
            ("parts", parts.len()),
            ("colors", colors.len()),
            ("opacity", opacity.len()),
        ] {
            if len != n {
                return Err(SurfaceError::Length {
                    what,
                    len,
                    vertices: n,
                });
            }
        }
        if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
            return Err(SurfaceError::NonFinitePosition {
                vertex: v,
                position: positions[v],
            });
        }
        if let Some(v) = colors.iter().position(|c| !c.is_finite()) {
            return Err(SurfaceError::NonFiniteColor {
                vertex: v,
                color: colors[v],
            });
        }
        if let Some(v) = opacity.iter().position(|o| !(0.0..=1.0).contains(o)) {
            return Err(SurfaceError::Opacity {
                vertex: v,
                opacity: opacity[v],
            });
        }
        if let Some(v) = parts.iter().position(|&p| p as usize >= num_parts) {
            return Err(SurfaceError::Part {
                vertex: v,
                part: parts[v],
                num_parts,
            });
        }
        if let Some(f) = faces
            .iter()
            .position(|f| f.iter().any(|&v| v as usize >= n))
        {
            return Err(SurfaceError::FaceIndex {
                face: f,
                indices: faces[f],
                vertices: n,
            });
        }

        let mut part_faces = vec![Vec::new(); num_parts];
        let mut cross_part_faces = 0;
        for (f, face) in faces.iter().enumerate() {
            let [a, b, c] = face.map(|v| parts[v as usize]);
            if a == b && b == c {
                part_faces[a as usize].push(f as u32);
            } else {
                cross_part_faces += 1;
            }
        }
        let part_trees = part_faces
            .iter()
            .map(|indices| {
                let own: Vec<[u32; 3]> = indices.iter().map(|&f| faces[f as usize]).collect();
                TriangleBvh::new(&positions, &own)
            })
            .collect();
        Ok(Self {
            positions,
            faces,
            parts,
            colors,
            opacity,
            num_parts,
            part_faces,
            part_trees,
            cross_part_faces,
        })
    }

    /// The state surface of a mesh field: hardened part labels, view-independent (degree-0 SH)
    /// colour and sigmoid opacity.
    pub(crate) fn from_field(field: &MeshField) -> Result<Self, SurfaceError> {
        field.validate()?;
        let parts = crate::mesh::topology::harden_parts(field);
        let colors = (0..field.num_vertices())
            .map(|v| field.dc_color(v))
            .collect();
        let opacity = field
            .opacity
            .iter()
            .map(|&logit| 1.0 / (1.0 + (-logit).exp()))
            .collect();
        Self::new(
            field.positions.clone(),
            field.faces.clone(),
            parts,
            colors,
            opacity,
            field.num_parts,
        )
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of parts K + 1, static base included.
    pub fn num_parts(&self) -> usize {
        self.num_parts
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Faces (vertex indices).
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// Hardened part label per vertex.
    pub fn parts(&self) -> &[u32] {
        &self.parts
    }

    /// Colour per vertex.
    pub fn colors(&self) -> &[Vec3] {
        &self.colors
    }

    /// Opacity per vertex.
    pub fn opacity(&self) -> &[f32] {
        &self.opacity
    }

    /// Number of faces of part `part` (0 for a label out of range).
    pub fn part_face_count(&self, part: usize) -> usize {
        self.part_faces.get(part).map_or(0, Vec::len)
    }

    /// Faces left out of the search because their vertices carry different labels.
    pub fn cross_part_faces(&self) -> usize {
        self.cross_part_faces
    }

    /// The point of `part`'s faces closest to `q` and that face's unit normal (either side);
    /// `None` for a part without faces or when the closest face is degenerate.
    pub(crate) fn closest_with_normal(&self, part: usize, q: DVec3) -> Option<(DVec3, DVec3)> {
        let hit = self.part_trees.get(part)?.closest(q.as_vec3())?;
        let face = self.faces[self.part_faces[part][hit.face as usize] as usize];
        let [a, b, c] = face.map(|v| self.positions[v as usize].as_dvec3());
        let normal = (b - a).cross(c - a).try_normalize()?;
        Some((hit.point.as_dvec3(), normal))
    }
}

/// The weights of the vertex-wise term: λ_c, λ_σ and the validity threshold η.
///
/// The paper gives no values for any of them; the defaults weigh colour and opacity equally and
/// accept matches within 2 cm, a few triangle sizes of a remeshed tabletop object.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct VertexMotionWeights {
    /// λ_c, weight of the squared colour difference.
    pub color: f32,
    /// λ_σ, weight of the squared opacity difference.
    pub opacity: f32,
    /// Largest closest-point distance (metres) of a valid match.
    pub max_distance: f32,
}

impl Default for VertexMotionWeights {
    fn default() -> Self {
        Self {
            color: 1.0,
            opacity: 1.0,
            max_distance: 0.02,
        }
    }
}

/// The vertex-wise term in one direction and its gradient with respect to the part motions.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexMotionLoss {
    /// L, normalised by the source's total vertex count as in the paper.
    pub loss: f64,
    /// Source vertices with a match within the distance threshold.
    pub valid: usize,
    /// Source vertices searched: those of movable parts whose target part has faces.
    pub considered: usize,
    /// Per part (`source.num_parts()` entries, part 0 always zero): Σ gᵢ and Σ gᵢ xᵢᵀ over the
    /// valid vertices, with gᵢ = ∂L/∂x̂ᵢ. By the chain rule through x̂ = A x + b these are ∂L/∂b
    /// and ∂L/∂A of that part's motion.
    pub per_part: Vec<PartSums>,
}

/// The vertex-wise motion consistency from `source` to `target`.
///
/// `motions[k] = (A_k, b_k)` carries part k of the source onto the target (x̂ = A_k x + b_k);
/// index 0, the static base, is never read but must be present. A_k is normally a rotation, but
/// nothing here relies on it: the gradient is with respect to all nine entries. For the backward
/// direction pass the surfaces swapped and the inverse motions (A_kᵀ, −A_kᵀ b_k).
///
/// Errors when the surfaces disagree on the number of parts, `motions` is too short or not
/// finite where used, or a weight is negative or not finite.
pub fn vertex_motion_loss(
    source: &StateSurface,
    target: &StateSurface,
    motions: &[(DMat3, DVec3)],
    weights: &VertexMotionWeights,
) -> Result<VertexMotionLoss, MotionLossError> {
    let num_parts = source.num_parts;
    if target.num_parts != num_parts {
        return Err(MotionLossError::PartCounts {
            source_parts: num_parts,
            target_parts: target.num_parts,
        });
    }
    if motions.len() < num_parts {
        return Err(MotionLossError::TooFewMotions {
            motions: motions.len(),
            parts: num_parts,
        });
    }
    if let Some(k) =
        (1..num_parts).find(|&k| !(motions[k].0.is_finite() && motions[k].1.is_finite()))
    {
        return Err(MotionLossError::NonFiniteMotion(k));
    }
    for (what, value) in [
        ("color", weights.color),
        ("opacity", weights.opacity),
        ("max_distance", weights.max_distance),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(MotionLossError::Weight { what, value });
        }
    }

    let mut result = VertexMotionLoss {
        loss: 0.0,
        valid: 0,
        considered: 0,
        per_part: vec![PartSums::default(); num_parts],
    };
    if source.positions.is_empty() {
        return Ok(result);
    }
    let inv_n = 1.0 / source.positions.len() as f64;
    let max_d2 = f64::from(weights.max_distance).powi(2);
    let (lambda_c, lambda_s) = (f64::from(weights.color), f64::from(weights.opacity));

    for (i, &x) in source.positions.iter().enumerate() {
        let part = source.parts[i] as usize;
        // The static base does not move; a part absent from the target has nothing to match.
        if part == 0 || target.part_trees[part].is_empty() {
            continue;
        }
        result.considered += 1;
        let x = x.as_dvec3();
        let (a, b) = motions[part];
        let moved = a * x + b;
        let Some(m) = closest_on_part(target, part, moved) else {
            continue;
        };
        if m.distance_squared > max_d2 {
            continue;
        }
        result.valid += 1;

        // Interpolated target attributes and the residuals against the source vertex.
        let corner_color = m.corners.map(|v| target.colors[v as usize].as_dvec3());
        let corner_opacity = m.corners.map(|v| f64::from(target.opacity[v as usize]));
        let color: DVec3 = (0..3).map(|j| corner_color[j] * m.beta[j]).sum();
        let opacity: f64 = (0..3).map(|j| corner_opacity[j] * m.beta[j]).sum();
        let dc = source.colors[i].as_dvec3() - color;
        let ds = f64::from(source.opacity[i]) - opacity;
        result.loss += inv_n * (lambda_c * dc.length_squared() + lambda_s * ds * ds);

        // ∂term/∂βⱼ = −2 (λ_c dc·cⱼ + λ_σ ds σⱼ), then through ∂β/∂x̂ of the region.
        let g: DVec3 = (0..3)
            .map(|j| {
                let d_beta =
                    -2.0 * (lambda_c * dc.dot(corner_color[j]) + lambda_s * ds * corner_opacity[j]);
                m.grad_beta[j] * d_beta
            })
            .sum();
        result.per_part[part].add(g * inv_n, x);
    }
    Ok(result)
}

/// The Voronoi region of a target triangle a moved vertex landed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Region {
    Face,
    /// The edge between two corners (positions in the face).
    Edge(usize, usize),
    Vertex(usize),
}

/// A moved vertex's match on the target, in f64: the tree (f32) picks the face and the region,
/// then β, ∂β/∂x̂ and the distance are evaluated here from x̂ in double precision, so the loss is
/// one smooth function per region and its gradient is exactly that function's.
#[derive(Debug, Clone, Copy)]
struct Match {
    /// The target face's vertex indices.
    corners: [u32; 3],
    /// Only the tests read it back (to check a perturbation keeps every vertex in its region).
    #[cfg_attr(not(test), expect(dead_code))]
    region: Region,
    beta: [f64; 3],
    grad_beta: [DVec3; 3],
    distance_squared: f64,
}

/// The closest point to `moved` on `target`'s faces of `part` (a part with at least one face).
fn closest_on_part(target: &StateSurface, part: usize, moved: DVec3) -> Option<Match> {
    let hit = target.part_trees[part].closest(moved.as_vec3())?;
    let face = target.part_faces[part][hit.face as usize];
    let corners = target.faces[face as usize];
    let p = corners.map(|v| target.positions[v as usize].as_dvec3());

    // closest_point_on_triangle reports off-face regions with exact zero weights.
    let w = hit.barycentric.to_array();
    let mut region = match w.map(|x| x == 0.0) {
        [false, false, false] => Region::Face,
        [true, false, false] => Region::Edge(1, 2),
        [false, true, false] => Region::Edge(2, 0),
        [false, false, true] => Region::Edge(0, 1),
        _ => Region::Vertex(w.iter().position(|&x| x != 0.0).unwrap_or(0)),
    };

    let mut beta = [0.0; 3];
    let mut grad_beta = [DVec3::ZERO; 3];
    if region == Region::Face {
        // β of the projection onto the plane, linear in x̂: with n = e₁ × e₂ and d = x̂ − a,
        // β_b = n·(d × e₂)/|n|² = d·(e₂ × n)/|n|², β_c = d·(n × e₁)/|n|², β_a = 1 − β_b − β_c.
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let n = e1.cross(e2);
        let nn = n.length_squared();
        if nn > 0.0 {
            grad_beta[1] = e2.cross(n) / nn;
            grad_beta[2] = n.cross(e1) / nn;
            grad_beta[0] = -(grad_beta[1] + grad_beta[2]);
            let d = moved - p[0];
            beta[1] = d.dot(grad_beta[1]);
            beta[2] = d.dot(grad_beta[2]);
            beta[0] = 1.0 - beta[1] - beta[2];
        } else {
            // Degenerate in f64 though not in f32: keep the tree's weights, held fixed.
            region = Region::Vertex(0);
            beta = w.map(f64::from);
        }
    }
    if let Region::Edge(i, j) = region {
        // The 1-D projection parameter t = (x̂ − pᵢ)·e/|e|² along e = pⱼ − pᵢ: βⱼ = t, βᵢ = 1 − t.
        let e = p[j] - p[i];
        let ee = e.length_squared();
        if ee > 0.0 {
            let t = (moved - p[i]).dot(e) / ee;
            beta[i] = 1.0 - t;
            beta[j] = t;
            grad_beta[j] = e / ee;
            grad_beta[i] = -e / ee;
        } else {
            region = Region::Vertex(i);
        }
    }
    if let Region::Vertex(k) = region {
        // The closest point is a corner (or a fixed blend of a degenerate face): β is constant.
        if beta == [0.0; 3] {
            beta[k] = 1.0;
        }
        grad_beta = [DVec3::ZERO; 3];
    }
    let point: DVec3 = (0..3).map(|j| p[j] * beta[j]).sum();
    Some(Match {
        corners,
        region,
        beta,
        grad_beta,
        distance_squared: (moved - point).length_squared(),
    })
}

mod error;
#[cfg(test)]
mod tests;
