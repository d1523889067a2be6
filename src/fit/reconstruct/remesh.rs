//! Hardening and part-aware remeshing (paper §3.1): part labels hardened by argmax, the
//! optimised faces dropped, and connectivity rebuilt by restricted Delaunay per part (or over
//! all vertices, the ablation), small floating pieces removed.

use glam::Vec3;

use super::config::{ReconstructionConfig, RemeshMode};
use super::results::RemeshStats;
use crate::mesh::topology::{
    compact, cross_part_faces, drop_small_components, face_part, median_edge, thin_vertices,
    vertex_normals,
};
use crate::mesh::{harden_parts, part_aware_remesh, restricted_delaunay};
use crate::raster::MeshField;

/// Hardened labels, new faces and what happened, for `field` remeshed with `config`'s mode.
pub(super) fn remesh(field: &MeshField, config: &ReconstructionConfig) -> (MeshField, RemeshStats) {
    let parts = harden_parts(field);
    let normals = vertex_normals(&field.positions, &field.faces);
    let mut stats = RemeshStats {
        mode: Some(config.remesh),
        faces_before: field.faces.len(),
        cross_part_faces_before: cross_part_faces(&field.faces, &parts),
        ..RemeshStats::default()
    };
    // Only vertices the optimised faces still use take part, thinned to an even spacing of
    // about one median edge: the soup's vertices come in tight clusters, which would leave the
    // restricted Delaunay step holes and slivers. Thinning never mixes parts.
    let (used, used_map) = compact(field, field.faces.clone());
    let used_parts: Vec<u32> = used_map.iter().map(|&v| parts[v as usize]).collect();
    let used_normals: Vec<Vec3> = used_map.iter().map(|&v| normals[v as usize]).collect();
    let cell = config.remesh_spacing * median_edge(&used.positions, &used.faces);
    let (used, used_normals) = if cell > 0.0 {
        thin_vertices(&used, &used_normals, &used_parts, cell)
    } else {
        (used, used_normals)
    };
    let used_parts = harden_parts(&used);
    let faces = match config.remesh {
        RemeshMode::PartAware => part_aware_remesh(
            &used.positions,
            Some(&used_normals),
            &used_parts,
            &config.remesh_options,
        ),
        RemeshMode::Global => {
            restricted_delaunay(&used.positions, Some(&used_normals), &config.remesh_options)
        }
    };
    stats.faces_built = faces.len();
    stats.cross_part_faces = cross_part_faces(&faces, &used_parts);
    // Floaters are judged per part, among that part's faces.
    let mut keep = vec![false; faces.len()];
    for k in 0..field.num_parts as u32 {
        let ids: Vec<usize> = (0..faces.len())
            .filter(|&f| face_part(&faces[f], &used_parts) == k)
            .collect();
        let own: Vec<[u32; 3]> = ids.iter().map(|&f| faces[f]).collect();
        for (&f, kept) in ids
            .iter()
            .zip(drop_small_components(&own, config.min_component_fraction))
        {
            keep[f] = kept;
        }
    }
    stats.floater_faces = keep.iter().filter(|k| !**k).count();
    let faces: Vec<[u32; 3]> = faces
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(f, _)| *f)
        .collect();
    let (mut out, _) = compact(&used, faces);
    stats.unused_vertices = field.num_vertices() - out.num_vertices();
    // Hardened logits: the label strongly, so renders of part logits show the labels.
    let labels = harden_parts(&out);
    let p = out.num_parts;
    for (v, &k) in labels.iter().enumerate() {
        let logits = &mut out.part_logits[v * p..(v + 1) * p];
        logits.fill(0.0);
        logits[k as usize] = 10.0;
    }
    (out, stats)
}
