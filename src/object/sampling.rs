//! Area-weighted surface sampling of a triangle mesh: the sampling CDF (which also tells whether a mesh has a
//! surface that can be sampled at all) and seeded, deterministic uniform surface points.
//!
//! The evaluation's Chamfer distance samples meshes with this; the dataset renderer applies the same check so
//! that every part it writes can be scored.

use glam::Vec3;

use crate::data::TriMesh;
use crate::rng::Rng;

/// Why a mesh cannot be sampled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SamplingError {
    /// Zero samples were asked for.
    #[error("the number of surface samples must be positive")]
    NoSamples,
    /// The mesh has no triangles.
    #[error("mesh has no triangles")]
    NoTriangles,
    /// A vertex position is NaN or infinite.
    #[error("vertex {index} has a non-finite position {position}")]
    NonFiniteVertex {
        /// Index of the vertex.
        index: usize,
        /// Its position.
        position: Vec3,
    },
    /// A triangle refers to a vertex the mesh does not have.
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    BadIndex {
        /// Index of the triangle.
        triangle: usize,
        /// The out-of-range vertex index.
        vertex: u32,
        /// Number of vertices in the mesh.
        vertices: usize,
    },
    /// The total area is zero or not finite.
    #[error("mesh has no surface to sample (total area {0})")]
    NoArea(f64),
}

/// Checks a mesh for sampling; returns the cumulative triangle areas (the sampling CDF) and the total area.
pub(crate) fn area_cdf(mesh: &TriMesh) -> Result<(Vec<f64>, f64), SamplingError> {
    if mesh.triangles.is_empty() {
        return Err(SamplingError::NoTriangles);
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(SamplingError::NonFiniteVertex {
            index: i,
            position: mesh.positions[i],
        });
    }
    let n = mesh.positions.len();
    let mut cdf = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0_f64;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(SamplingError::BadIndex {
                triangle: t,
                vertex: bad,
                vertices: n,
            });
        }
        let [a, b, c] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
        total += 0.5 * (b - a).cross(c - a).length();
        cdf.push(total);
    }
    if !(total.is_finite() && total > 0.0) {
        return Err(SamplingError::NoArea(total));
    }
    Ok((cdf, total))
}

/// Uniform in [0, 1) with 53 random bits (triangle choice on meshes with millions of faces stays unbiased).
fn unit_f64(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` points uniformly distributed over the surface of `mesh` (triangle chosen by area, then a uniform
/// point in it), reproducible from `seed`. Errors for meshes without a samplable surface (no triangles, zero
/// area, bad indices, non-finite vertices) or `count == 0`.
pub fn sample_surface(mesh: &TriMesh, count: usize, seed: u64) -> Result<Vec<Vec3>, SamplingError> {
    if count == 0 {
        return Err(SamplingError::NoSamples);
    }
    let (cdf, total) = area_cdf(mesh)?;
    let mut rng = Rng::new(seed);
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        let target = unit_f64(&mut rng) * total;
        // First triangle whose cumulative area exceeds the target; zero-area triangles are never chosen.
        let t = cdf.partition_point(|&c| c <= target).min(cdf.len() - 1);
        let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize].as_dvec3());
        // sqrt makes the barycentric point uniform over the triangle's area.
        let r1 = unit_f64(&mut rng).sqrt();
        let r2 = unit_f64(&mut rng);
        let p = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
        points.push(p.as_vec3());
    }
    Ok(points)
}
