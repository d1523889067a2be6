//! Densification and pruning (paper §3.1): in a window of the optimisation, visible faces
//! larger than a few pixels split 1 → 4, and faces that are never seen, transparent or
//! oversized are dropped.

use super::config::DensifyConfig;
use crate::data::Camera;
use crate::mesh::topology::{longest_edge, retain_faces, split_faces};
use crate::raster::MeshField;

/// Pixels per metre at the field's median distance from the cameras.
pub(super) fn pixels_per_metre(field: &MeshField, cameras: &[Camera]) -> f32 {
    let Some(camera) = cameras.first() else {
        return 1.0;
    };
    let mut d: Vec<f32> = field
        .positions
        .iter()
        .step_by((field.positions.len() / 512).max(1))
        .map(|p| p.distance(camera.position()))
        .collect();
    if d.is_empty() {
        return 1.0;
    }
    d.sort_by(f32::total_cmp);
    camera.intrinsics.fx / d[d.len() / 2].max(1e-6)
}

fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}

/// One densify-and-prune edit of `field` from the window's face statistics. Returns the new
/// field, its new → old vertex map, and (split, pruned) face counts.
pub(super) fn densify_and_prune(
    field: &MeshField,
    stats: &[(f32, u32)],
    config: &DensifyConfig,
    px_per_m: f32,
) -> (MeshField, Vec<u32>, usize, usize) {
    let n = field.faces.len();
    let mut keep = vec![true; n];
    let mut candidates = Vec::new();
    for (f, face) in field.faces.iter().enumerate() {
        let (weight, _) = stats.get(f).copied().unwrap_or((0.0, 0));
        let edge_px = longest_edge(&field.positions, face) * px_per_m;
        let opacity = face
            .iter()
            .map(|&v| sigmoid(field.opacity[v as usize]))
            .sum::<f32>()
            / 3.0;
        if weight < config.prune_weight
            || opacity < config.prune_opacity
            || edge_px > config.oversize_pixels
        {
            keep[f] = false;
        } else if weight >= config.split_weight && edge_px >= config.split_pixels {
            candidates.push((weight * edge_px * edge_px, f));
        }
    }
    let pruned = keep.iter().filter(|k| !**k).count();
    let budget = config.max_faces.saturating_sub(n - pruned) / 3;
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut selected = vec![false; n];
    for &(_, f) in candidates.iter().take(budget) {
        selected[f] = true;
    }
    let split = candidates.len().min(budget);
    let (split_field, split_map) = split_faces(field, &selected);
    // split_faces keeps face order, replacing each selected face by its four children.
    let keep_after: Vec<bool> = (0..n)
        .flat_map(|f| std::iter::repeat_n(keep[f], if selected[f] { 4 } else { 1 }))
        .collect();
    let (out, map) = retain_faces(&split_field, &keep_after);
    let map = map.iter().map(|&v| split_map[v as usize]).collect();
    (out, map, split, pruned)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optim::FRESH;
    use glam::Vec3;

    #[test]
    fn densify_splits_visible_large_faces_and_prunes_invisible_ones() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let field = MeshField::new(positions, vec![[0, 1, 2], [3, 4, 5]], 1, 0.0);
        let config = DensifyConfig {
            split_pixels: 2.0,
            ..DensifyConfig::default()
        };
        // 10 px per metre: both faces are ~14 px; face 0 seen, face 1 never.
        let (out, map, split, pruned) =
            densify_and_prune(&field, &[(0.9, 40), (0.0, 0)], &config, 10.0);
        assert_eq!((split, pruned), (1, 1));
        assert_eq!(out.faces.len(), 4);
        assert_eq!(out.num_vertices(), 6);
        // The split face's corners keep their moments; its three midpoints start fresh.
        let mut old: Vec<u32> = map.iter().copied().filter(|&m| m != FRESH).collect();
        old.sort();
        assert_eq!(old, vec![0, 1, 2]);
        for (new, &m) in map.iter().enumerate() {
            if m != FRESH {
                assert_eq!(out.positions[new], field.positions[m as usize]);
            }
        }
        out.validate().unwrap();
    }
}
