//! Per-part first moments of a position gradient: what the rigid-motion maths needs from the
//! millions of per-vertex gradients. For moved vertices x̂ᵢ = A xᵢ + b, the loss gradient reaches
//! the affine map only through Σ gᵢ (for b) and Σ gᵢ xᵢᵀ (for A), summed over a part's vertices;
//! the pixel-wise term reduces them on the GPU, the vertex-wise term on the CPU, and both hand
//! them to [`super::motion`] in this form.

use glam::{DMat3, DVec3};

/// Σ gᵢ and Σ gᵢ xᵢᵀ over one part's vertices, where gᵢ = ∂L/∂x̂ᵢ at the moved position and xᵢ
/// the vertex's position before the motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartSums {
    /// Σ gᵢ.
    pub g: DVec3,
    /// Σ gᵢ xᵢᵀ (column j holds Σ gᵢ xᵢⱼ).
    pub gx: DMat3,
    /// Vertices that contributed.
    pub count: u32,
}

// Not derived: glam's matrices default to the identity, the sums must start at zero.
impl Default for PartSums {
    fn default() -> Self {
        Self {
            g: DVec3::ZERO,
            gx: DMat3::ZERO,
            count: 0,
        }
    }
}

impl PartSums {
    /// Adds one vertex: gradient `g` at the moved position of source point `x`.
    pub fn add(&mut self, g: DVec3, x: DVec3) {
        self.g += g;
        self.gx += outer(g, x);
        self.count += 1;
    }

    /// The sum of two partial sums.
    pub fn merged(self, other: PartSums) -> PartSums {
        PartSums {
            g: self.g + other.g,
            gx: self.gx + other.gx,
            count: self.count + other.count,
        }
    }

    /// Both sums scaled by `s` (a loss weight).
    pub fn scaled(self, s: f64) -> PartSums {
        PartSums {
            g: self.g * s,
            gx: self.gx * s,
            count: self.count,
        }
    }
}

/// a bᵀ.
pub(crate) fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
