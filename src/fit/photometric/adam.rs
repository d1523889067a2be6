//! Adam over the four parameter groups of a mesh field on the GPU (positions, SH
//! coefficients, opacity logits, part logits), carried across topology edits.

use serde::Serialize;

use crate::gpu::{GpuContext, GpuResult};
use crate::optim::{Adam, AdamConfig, AdamGroup};
use crate::raster::{GpuField, SH_FLOATS};

/// Learning rates of the mesh field's four parameter groups.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FieldLearningRates {
    pub position: f32,
    pub sh: f32,
    pub opacity: f32,
    pub part: f32,
}

/// Adam over a [`GpuField`]'s positions, SH coefficients, opacity logits and part logits.
pub struct FieldAdam {
    adam: Adam,
    groups: Vec<AdamGroup>,
}

impl FieldAdam {
    pub fn new(ctx: &GpuContext, field: &GpuField, lr: FieldLearningRates) -> GpuResult<Self> {
        let adam = Adam::new(ctx)?;
        let nv = field.num_vertices;
        let groups = vec![
            adam.group(
                ctx,
                "positions",
                &field.positions,
                &field.grad_positions,
                4 * nv,
                AdamConfig::with_lr(lr.position),
            )?,
            adam.group(
                ctx,
                "sh",
                &field.sh,
                &field.grad_sh,
                nv * SH_FLOATS as u32,
                AdamConfig::with_lr(lr.sh),
            )?,
            adam.group(
                ctx,
                "opacity",
                &field.opacity,
                &field.grad_opacity,
                nv,
                AdamConfig::with_lr(lr.opacity),
            )?,
            adam.group(
                ctx,
                "part_logits",
                &field.part_logits,
                &field.grad_part_logits,
                nv * field.num_parts,
                AdamConfig::with_lr(lr.part),
            )?,
        ];
        Ok(Self { adam, groups })
    }

    /// Sets the position learning rate (the one group with a schedule).
    pub(crate) fn set_position_lr(&mut self, lr: f32) {
        self.groups[0].set_lr(lr);
    }

    /// Sets every group's learning rate.
    pub fn set_rates(&mut self, lr: FieldLearningRates) {
        for (group, lr) in self
            .groups
            .iter_mut()
            .zip([lr.position, lr.sh, lr.opacity, lr.part])
        {
            group.set_lr(lr);
        }
    }

    /// Moves the optimiser onto `field` after a topology edit: `map[new vertex] = old vertex`, or
    /// [`crate::optim::FRESH`] for a vertex that starts with zero moments.
    pub fn remap(&mut self, ctx: &GpuContext, field: &GpuField, map: &[u32]) -> GpuResult<()> {
        let buffers = [
            (&field.positions, &field.grad_positions, 4),
            (&field.sh, &field.grad_sh, SH_FLOATS as u32),
            (&field.opacity, &field.grad_opacity, 1),
            (&field.part_logits, &field.grad_part_logits, field.num_parts),
        ];
        for (group, (params, grads, stride)) in self.groups.iter_mut().zip(buffers) {
            self.adam.remap(ctx, group, params, grads, map, stride)?;
        }
        Ok(())
    }

    /// Records one step of every group.
    pub fn encode_step(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
    ) -> GpuResult<()> {
        let mut refs: Vec<&mut AdamGroup> = self.groups.iter_mut().collect();
        self.adam.encode_step(ctx, encoder, &mut refs)
    }
}
