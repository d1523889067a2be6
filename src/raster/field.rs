//! The part-aware mesh field of the paper (§3.1): per vertex a position, SH colour coefficients,
//! an opacity logit and K + 1 part logits; per face three vertex indices. [`MeshField`] is the
//! CPU copy, [`GpuField`] the buffers the kernels read, their gradients, and the vertex → corner
//! CSR through which shared vertices gather gradients from all their faces.

use glam::Vec3;

use super::kernels::{MAX_PARTS, SH_COEFFS};
use crate::gpu::{GpuContext, GpuError, GpuResult};

/// Floats of SH coefficients per vertex (16 coefficients × RGB, `[coeff][rgb]`).
pub const SH_FLOATS: usize = SH_COEFFS * 3;

/// SH degree-0 basis constant: a DC coefficient c gives colour `C0 · c + 0.5`.
pub const SH_C0: f32 = 0.282_094_8;

/// Why a [`MeshField`] is inconsistent ([`MeshField::validate`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FieldError {
    /// A part count outside 1..=`MAX_PARTS`.
    #[error(
        "num_parts is {num_parts}, expected 1 to {max} (static base + up to {} movable parts)",
        MAX_PARTS - 1,
        max = MAX_PARTS
    )]
    PartCount {
        /// The field's part count.
        num_parts: usize,
    },
    /// A per-vertex array whose length does not match the vertex count.
    #[error("{what} has {len} values, expected {want} for {vertices} vertices")]
    Length {
        /// The array's name.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length the vertex count implies.
        want: usize,
        /// The vertex count.
        vertices: usize,
    },
    /// A face with a vertex index out of range.
    #[error("face {face} references vertex {indices:?}, but there are only {vertices} vertices")]
    FaceIndex {
        /// Index of the face.
        face: usize,
        /// Its vertex indices.
        indices: [u32; 3],
        /// The vertex count.
        vertices: usize,
    },
    /// A vertex position with a NaN or infinite coordinate.
    #[error("vertex {0} has a non-finite position")]
    NonFinite(usize),
}

/// A triangle mesh whose vertices carry appearance, opacity and part logits.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshField {
    /// Vertex positions (world, metres).
    pub positions: Vec<Vec3>,
    /// `SH_FLOATS` per vertex: coefficient-major, RGB within a coefficient.
    pub sh: Vec<f32>,
    /// Opacity logit per vertex (σ = sigmoid).
    pub opacity: Vec<f32>,
    /// `num_parts` logits per vertex.
    pub part_logits: Vec<f32>,
    /// Number of rigid parts K + 1 (static base included), 1 ..= 16.
    pub num_parts: usize,
    /// Vertex indices per face.
    pub faces: Vec<[u32; 3]>,
}

impl MeshField {
    /// A field over `positions` and `faces` with grey colour, the given opacity logit and
    /// uniform part logits.
    pub fn new(positions: Vec<Vec3>, faces: Vec<[u32; 3]>, num_parts: usize, opacity: f32) -> Self {
        let n = positions.len();
        Self {
            sh: vec![0.0; n * SH_FLOATS],
            opacity: vec![opacity; n],
            part_logits: vec![0.0; n * num_parts],
            positions,
            num_parts,
            faces,
        }
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Sets vertex `v`'s view-independent colour (degree-0 SH), higher bands zeroed.
    pub(crate) fn set_color(&mut self, v: usize, rgb: Vec3) {
        let c = &mut self.sh[v * SH_FLOATS..(v + 1) * SH_FLOATS];
        c.fill(0.0);
        for (k, value) in rgb.to_array().into_iter().enumerate() {
            c[k] = (value - 0.5) / SH_C0;
        }
    }

    /// Vertex `v`'s view-independent colour (the degree-0 SH term, as [`MeshField::set_color`] sets it),
    /// in the images' encoding, unclamped.
    pub(crate) fn dc_color(&self, v: usize) -> Vec3 {
        let sh = &self.sh[v * SH_FLOATS..v * SH_FLOATS + 3];
        Vec3::new(sh[0], sh[1], sh[2]) * SH_C0 + 0.5
    }

    /// Checks that every array has the length the vertex count implies and every index is valid.
    pub fn validate(&self) -> Result<(), FieldError> {
        let n = self.num_vertices();
        if !(1..=MAX_PARTS).contains(&self.num_parts) {
            return Err(FieldError::PartCount {
                num_parts: self.num_parts,
            });
        }
        for (what, len, want) in [
            ("sh", self.sh.len(), n * SH_FLOATS),
            ("opacity", self.opacity.len(), n),
            ("part_logits", self.part_logits.len(), n * self.num_parts),
        ] {
            if len != want {
                return Err(FieldError::Length {
                    what,
                    len,
                    want,
                    vertices: n,
                });
            }
        }
        if let Some((f, face)) = self
            .faces
            .iter()
            .enumerate()
            .find(|(_, face)| face.iter().any(|&i| i as usize >= n))
        {
            return Err(FieldError::FaceIndex {
                face: f,
                indices: *face,
                vertices: n,
            });
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(FieldError::NonFinite(v));
        }
        Ok(())
    }
}

/// Gradients of a [`MeshField`]'s parameters, laid out like the field.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldGradients {
    pub positions: Vec<Vec3>,
    pub sh: Vec<f32>,
    pub opacity: Vec<f32>,
    pub part_logits: Vec<f32>,
}

/// The mesh field on the GPU: parameters, their gradients (overwritten by each backward pass),
/// this view's vertex colours and the vertex → corner CSR.
pub struct GpuField {
    /// `vec4` per vertex (w unused, its gradient always 0).
    pub positions: wgpu::Buffer,
    pub sh: wgpu::Buffer,
    pub opacity: wgpu::Buffer,
    pub part_logits: wgpu::Buffer,
    pub faces: wgpu::Buffer,
    pub csr_offsets: wgpu::Buffer,
    pub csr_corners: wgpu::Buffer,
    pub colors: wgpu::Buffer,
    pub grad_positions: wgpu::Buffer,
    pub grad_sh: wgpu::Buffer,
    pub grad_opacity: wgpu::Buffer,
    pub grad_part_logits: wgpu::Buffer,
    pub grad_colors: wgpu::Buffer,
    pub num_vertices: u32,
    pub num_faces: u32,
    pub num_parts: u32,
}

impl GpuField {
    /// Uploads `field`; errors name the array that does not fit or is inconsistent.
    pub fn upload(ctx: &GpuContext, field: &MeshField) -> GpuResult<Self> {
        field
            .validate()
            .map_err(|e| GpuError::InvalidInput(format!("invalid mesh field: {e}")))?;
        let n = field.num_vertices();
        let too_many = |what: &str, count: usize| GpuError::TooManyElements {
            what: what.to_string(),
            count: count as u64,
            max: u64::from(u32::MAX / 3),
        };
        if n > (u32::MAX / 3) as usize {
            return Err(too_many("mesh vertices", n));
        }
        if field.faces.len() > (u32::MAX / 3) as usize {
            return Err(too_many("mesh faces", field.faces.len()));
        }
        let positions: Vec<[f32; 4]> = field
            .positions
            .iter()
            .map(|p| p.extend(0.0).into())
            .collect();
        let faces: Vec<u32> = field.faces.iter().flatten().copied().collect();
        let (csr_offsets, csr_corners) = vertex_corners(n, &field.faces);
        let vec4_bytes = (n * 16) as u64;
        Ok(Self {
            positions: ctx.storage_buffer("mesh.positions", &positions)?,
            sh: ctx.storage_buffer("mesh.sh", &field.sh)?,
            opacity: ctx.storage_buffer("mesh.opacity", &field.opacity)?,
            part_logits: ctx.storage_buffer("mesh.part_logits", &field.part_logits)?,
            faces: ctx.storage_buffer("mesh.faces", &faces)?,
            csr_offsets: ctx.storage_buffer("mesh.csr_offsets", &csr_offsets)?,
            csr_corners: ctx.storage_buffer("mesh.csr_corners", &csr_corners)?,
            colors: ctx.storage_buffer_zeroed("mesh.colors", vec4_bytes)?,
            grad_positions: ctx.storage_buffer_zeroed("mesh.grad_positions", vec4_bytes)?,
            grad_sh: ctx.storage_buffer_zeroed("mesh.grad_sh", (field.sh.len() * 4) as u64)?,
            grad_opacity: ctx.storage_buffer_zeroed("mesh.grad_opacity", (n * 4) as u64)?,
            grad_part_logits: ctx.storage_buffer_zeroed(
                "mesh.grad_part_logits",
                (field.part_logits.len() * 4) as u64,
            )?,
            grad_colors: ctx.storage_buffer_zeroed("mesh.grad_colors", vec4_bytes)?,
            num_vertices: n as u32,
            num_faces: field.faces.len() as u32,
            num_parts: field.num_parts as u32,
        })
    }

    /// Reads the parameters back (faces included) as a [`MeshField`].
    pub async fn download(&self, ctx: &GpuContext) -> GpuResult<MeshField> {
        let n = self.num_vertices as usize;
        let positions: Vec<[f32; 4]> = ctx.read_buffer(&self.positions, n).await?;
        let faces: Vec<u32> = ctx
            .read_buffer(&self.faces, 3 * self.num_faces as usize)
            .await?;
        Ok(MeshField {
            positions: positions
                .iter()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
            sh: ctx.read_buffer(&self.sh, n * SH_FLOATS).await?,
            opacity: ctx.read_buffer(&self.opacity, n).await?,
            part_logits: ctx
                .read_buffer(&self.part_logits, n * self.num_parts as usize)
                .await?,
            num_parts: self.num_parts as usize,
            faces: faces.chunks_exact(3).map(|f| [f[0], f[1], f[2]]).collect(),
        })
    }

    /// Reads the gradients of the last backward pass.
    pub(crate) async fn read_gradients(&self, ctx: &GpuContext) -> GpuResult<FieldGradients> {
        let n = self.num_vertices as usize;
        let positions: Vec<[f32; 4]> = ctx.read_buffer(&self.grad_positions, n).await?;
        Ok(FieldGradients {
            positions: positions
                .iter()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
            sh: ctx.read_buffer(&self.grad_sh, n * SH_FLOATS).await?,
            opacity: ctx.read_buffer(&self.grad_opacity, n).await?,
            part_logits: ctx
                .read_buffer(&self.grad_part_logits, n * self.num_parts as usize)
                .await?,
        })
    }
}

/// CSR of the corners (3 · face + i) each vertex appears in: offsets (n + 1) and corner ids.
pub fn vertex_corners(num_vertices: usize, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; num_vertices + 1];
    for &v in faces.iter().flatten() {
        offsets[v as usize + 1] += 1;
    }
    for i in 0..num_vertices {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut corners = vec![0u32; faces.len() * 3];
    for (c, &v) in faces.iter().flatten().enumerate() {
        corners[fill[v as usize] as usize] = c as u32;
        fill[v as usize] += 1;
    }
    (offsets, corners)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csr_lists_every_corner_of_each_vertex() {
        let faces = [[0, 1, 2], [2, 1, 3], [3, 4, 2]];
        let (offsets, corners) = vertex_corners(5, &faces);
        assert_eq!(offsets, vec![0, 1, 3, 6, 8, 9]);
        let of = |v: usize| corners[offsets[v] as usize..offsets[v + 1] as usize].to_vec();
        assert_eq!(of(2), vec![2, 3, 8]);
        assert_eq!(of(3), vec![5, 6]);
    }

    #[test]
    fn validation_names_the_problem() {
        let mut f = MeshField::new(vec![Vec3::ZERO; 3], vec![[0, 1, 3]], 2, 0.0);
        assert!(f.validate().unwrap_err().to_string().contains("face 0"));
        f.faces = vec![[0, 1, 2]];
        assert!(f.validate().is_ok());
        f.opacity.pop();
        assert!(f.validate().unwrap_err().to_string().contains("opacity"));
    }
}
