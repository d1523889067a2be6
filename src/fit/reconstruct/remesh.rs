//! Hardening and part-aware remeshing (paper §3.1): part labels hardened by argmax, the
//! optimised faces dropped, and connectivity rebuilt by restricted Delaunay per part (or over
//! all vertices, the ablation), small floating pieces removed, short holes closed.

use glam::Vec3;

use super::config::{ReconstructionConfig, RemeshMode, SurfaceSource, UNCHECKED_HOLE_EDGES};
use super::free_space::{FreeSpace, evidence_states};
use super::results::RemeshStats;
use crate::articulation::observed::ObservedState;
use crate::data::State;
use crate::mesh::topology::{
    compact, cross_part_faces, drop_small_components, face_part, median_edge, thin_vertices,
    vertex_normals,
};
use crate::mesh::{
    close_short_holes, harden_parts, part_aware_remesh, restricted_delaunay, stitch_rims,
};
use crate::raster::{MeshField, SH_FLOATS};

/// Fewer measured points than this and a part keeps its optimised vertices.
const MIN_MEASURED_POINTS: usize = 32;

/// Over measured points (normals from depth, not from a 64² fit), neighbours join up to 90°
/// apart, so the walls of a box meet at their crease instead of staying separate sheets; a thin
/// part's two sides (180°) still stay apart. Quick suite: split parts 4 -> 0, boundary edges
/// 3.8 -> 2.4 %, CD-s 10.43 -> 10.14 mm, test PSNR 27.26 -> 27.39 dB, though the eyeglasses lose
/// 3.8 dB and the knife 1.8 dB (docs/results.md, "Measured surfaces").
const MEASURED_MIN_NORMAL_COSINE: f32 = 0.0;

/// Hardened labels, new faces and what happened, for `field` remeshed with `config`'s mode, over
/// the `measured` part surfaces where given (see [`SurfaceSource::Measured`]); hole-fill faces
/// the training views of `free` saw through are left out (state `state`'s reconstruction).
pub(super) fn remesh(
    field: &MeshField,
    measured: Option<&ObservedState>,
    free: Option<&FreeSpace>,
    state: State,
    config: &ReconstructionConfig,
) -> (MeshField, RemeshStats) {
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
    let mut options = config.remesh_options;
    let (used, used_normals) = match measured {
        Some(m) if config.surface == SurfaceSource::Measured => {
            options.min_normal_cosine = MEASURED_MIN_NORMAL_COSINE;
            // About two faces per vertex: the preset's face cap bounds the measured points.
            with_measured_parts(&used, &used_normals, m, config.densify.max_faces / 2)
        }
        _ => (used, used_normals),
    };
    let used_parts = harden_parts(&used);
    let faces = match config.remesh {
        RemeshMode::PartAware => {
            part_aware_remesh(&used.positions, Some(&used_normals), &used_parts, &options)
        }
        RemeshMode::Global => restricted_delaunay(&used.positions, Some(&used_normals), &options),
    };
    stats.faces_built = faces.len();
    stats.cross_part_faces = cross_part_faces(&faces, &used_parts);
    // Floaters are judged per part, among that part's faces; then the part's short holes are
    // closed, the new faces after all the kept ones.
    let mut keep = vec![false; faces.len()];
    let mut fills = Vec::new();
    for k in 0..field.num_parts as u32 {
        let ids: Vec<usize> = (0..faces.len())
            .filter(|&f| face_part(&faces[f], &used_parts) == k)
            .collect();
        let own: Vec<[u32; 3]> = ids.iter().map(|&f| faces[f]).collect();
        let kept = drop_small_components(&own, config.min_component_fraction);
        for (&f, &kept) in ids.iter().zip(&kept) {
            keep[f] = kept;
        }
        let own: Vec<[u32; 3]> = own
            .into_iter()
            .zip(kept)
            .filter(|(_, k)| *k)
            .map(|(f, _)| f)
            .collect();
        // The views that check this part's fills, and its median edge (the evidence's margin);
        // without free space nothing is checked.
        let check = free.map(|f| {
            let states = evidence_states(k as usize, state);
            (f, states, median_edge(&used.positions, &own))
        });
        let keep = |face: &[u32; 3]| {
            check.as_ref().is_none_or(|(f, states, spacing)| {
                !f.refuses(states, &used.positions, face, k as usize, *spacing)
            })
        };
        // Fills are trusted as far as the views can check them: the static base's against both
        // states' views, so its loops close up to the limit; every other loop stays short.
        let checked = k == 0 && check.is_some();
        let max_edges = if checked {
            config.close_holes
        } else {
            config.close_holes.min(UNCHECKED_HOLE_EDGES)
        };
        let closing = Closing {
            max_edges,
            rim_gap: config.rim_gap,
            keep: &keep,
        };
        fills.extend(close_part(&used.positions, own, &closing, &mut stats));
    }
    stats.floater_faces = keep.iter().filter(|k| !**k).count();
    let faces: Vec<[u32; 3]> = faces
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(f, _)| *f)
        .chain(fills)
        .collect();
    let (mut out, _) = compact(&used, faces);
    stats.unused_vertices = field.num_vertices().saturating_sub(out.num_vertices());
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

/// How one part's holes and rims are closed.
struct Closing<'a> {
    /// Longest hole loop closed (edges).
    max_edges: usize,
    /// Rim gap in median edges (0: rims stay open).
    rim_gap: f32,
    /// Whether a fill face may stay (the views did not see through it).
    keep: &'a dyn Fn(&[u32; 3]) -> bool,
}

/// The faces that close one part's `own` faces: its short holes, then its rims where a thin
/// part's two sides run side by side, then the short holes the zips left.
fn close_part(
    positions: &[Vec3],
    mut own: Vec<[u32; 3]>,
    closing: &Closing,
    stats: &mut RemeshStats,
) -> Vec<[u32; 3]> {
    let kept = own.len();
    let close_holes = |own: &mut Vec<[u32; 3]>, stats: &mut RemeshStats| {
        let (fill, holes) = close_short_holes(positions, own, closing.max_edges, closing.keep);
        stats.holes.loops += holes.loops;
        stats.holes.closed += holes.closed;
        stats.holes.faces += holes.faces;
        stats.holes.refused_faces += holes.refused_faces;
        own.extend(fill);
    };
    close_holes(&mut own, stats);
    if closing.rim_gap > 0.0 && !own.is_empty() {
        let gap = closing.rim_gap * median_edge(positions, &own);
        let (strip, rims) = stitch_rims(positions, &own, gap);
        stats.rims.zipped += rims.zipped;
        stats.rims.faces += rims.faces;
        if !strip.is_empty() {
            own.extend(strip);
            close_holes(&mut own, stats);
        }
    }
    own.split_off(kept)
}

/// Whether `measured` has enough points of each of `num_parts` parts to replace them all.
pub(super) fn measures_every_part(measured: &ObservedState, num_parts: usize) -> bool {
    (0..num_parts).all(|k| measures_part(measured, k))
}

/// Whether `measured` has enough points of part `k` to replace its optimised vertices.
fn measures_part(measured: &ObservedState, k: usize) -> bool {
    measured
        .parts
        .get(k)
        .is_some_and(|c| c.points.len() >= MIN_MEASURED_POINTS)
}

/// `thinned`'s vertices with every part that `measured` has enough points of replaced by those
/// points (their normals and mean pixel colours; opacity and logits hardened to the part),
/// coarsened where the measured parts have more than `max_points` points in all (each to its
/// share).
fn with_measured_parts(
    thinned: &MeshField,
    normals: &[Vec3],
    measured: &ObservedState,
    max_points: usize,
) -> (MeshField, Vec<Vec3>) {
    let parts = harden_parts(thinned);
    let p = thinned.num_parts;
    let replaced = |k: usize| measures_part(measured, k);
    let kept: Vec<usize> = (0..thinned.num_vertices())
        .filter(|&v| !replaced(parts[v] as usize))
        .collect();
    let mut positions: Vec<Vec3> = kept.iter().map(|&v| thinned.positions[v]).collect();
    let mut out_normals: Vec<Vec3> = kept.iter().map(|&v| normals[v]).collect();
    let mut colors = Vec::new();
    let mut labels = Vec::new();
    let total: usize = (0..p)
        .filter(|&k| replaced(k))
        .map(|k| measured.parts[k].points.len())
        .sum();
    for k in (0..p).filter(|&k| replaced(k)) {
        let own = measured.parts[k].points.len();
        let share = (max_points as f64 * own as f64 / total.max(1) as f64) as usize;
        let cloud = &measured.parts[k].coarsened(share.max(MIN_MEASURED_POINTS));
        positions.extend(&cloud.points);
        out_normals.extend(&cloud.normals);
        colors.extend(&cloud.colors);
        labels.extend(std::iter::repeat_n(k, cloud.points.len()));
    }
    let mut out = MeshField::new(positions, Vec::new(), p, 4.0);
    for (i, &v) in kept.iter().enumerate() {
        out.sh[i * SH_FLOATS..(i + 1) * SH_FLOATS]
            .copy_from_slice(&thinned.sh[v * SH_FLOATS..(v + 1) * SH_FLOATS]);
        out.opacity[i] = thinned.opacity[v];
        out.part_logits[i * p..(i + 1) * p]
            .copy_from_slice(&thinned.part_logits[v * p..(v + 1) * p]);
    }
    for (j, (&color, &k)) in colors.iter().zip(&labels).enumerate() {
        let v = kept.len() + j;
        out.set_color(v, color);
        out.part_logits[v * p + k] = 10.0;
    }
    (out, out_normals)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::articulation::observed::PartCloud;
    use crate::mesh::{MAX_HOLE_EDGES, edge_counts};

    /// A flat square of `n`² points at height `z`, normals up.
    fn square(n: usize, z: f32) -> PartCloud {
        let points: Vec<Vec3> = (0..n * n)
            // Jittered: a regular grid's cocircular points have no unique Delaunay umbrellas.
            .map(|i| {
                let jitter = ((i * 7919) % 13) as f32 * 2e-4;
                Vec3::new(
                    (i % n) as f32 * 0.01 + jitter,
                    (i / n) as f32 * 0.01 - jitter,
                    z,
                )
            })
            .collect();
        PartCloud {
            normals: vec![Vec3::Z; points.len()],
            colors: vec![Vec3::new(0.8, 0.2, 0.1); points.len()],
            pixels: points.len(),
            labelled: points.len(),
            points,
            noise: 0.0,
        }
    }

    #[test]
    fn measured_parts_replace_the_optimised_ones_that_have_enough_points() {
        // Optimised: part 0 at z = 0, part 1 at z = 1 (three vertices each).
        let positions = [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0].map(|z| Vec3::new(0.0, 0.0, z));
        let mut field = MeshField::new(positions.to_vec(), Vec::new(), 2, 0.0);
        for v in 0..6 {
            field.part_logits[2 * v + v / 3] = 5.0;
        }
        let normals = vec![Vec3::Z; 6];
        // Measured: part 0 densely at z = 0.5, part 1 with too few points to trust.
        let measured = ObservedState {
            noise: None,
            parts: vec![square(10, 0.5), square(3, 2.0)],
            views_with_depth: 1,
            views: 1,
            stride: 1,
        };
        let (out, out_normals) = with_measured_parts(&field, &normals, &measured, 1000);
        assert_eq!(out.num_vertices(), 3 + 100);
        assert_eq!(out_normals.len(), out.num_vertices());
        let parts = harden_parts(&out);
        for (position, part) in out.positions.iter().zip(&parts) {
            let z = position.z;
            match part {
                0 => assert_eq!(z, 0.5, "part 0 is measured"),
                _ => assert_eq!(z, 1.0, "part 1 keeps its optimised vertices"),
            }
        }
        assert_eq!(parts.iter().filter(|&&k| k == 0).count(), 100);
        let c = out.dc_color(3 + 7);
        assert!((c - Vec3::new(0.8, 0.2, 0.1)).length() < 1e-5, "{c}");
        // Over a budget, the measured parts are coarsened to it.
        let (coarse, _) = with_measured_parts(&field, &normals, &measured, 40);
        let coarse_parts = harden_parts(&coarse);
        let measured_points = coarse_parts.iter().filter(|&&k| k == 0).count();
        assert!((9..=40).contains(&measured_points), "{measured_points}");
        // And they remesh into a surface over the measured points.
        let config = ReconstructionConfig {
            surface: SurfaceSource::Measured,
            ..ReconstructionConfig::preset(crate::fit::preset::Preset::Tiny)
        };
        let (remeshed, stats) = remesh(&field, Some(&measured), None, State::Start, &config);
        assert_eq!(stats.cross_part_faces, 0);
        assert!(remeshed.faces.len() > 100, "{} faces", remeshed.faces.len());
    }

    #[test]
    fn a_short_hole_in_a_measured_part_is_closed_and_the_rim_left_open() {
        // A measured sheet with a 2x2 gap of points in its middle.
        let mut sheet = square(16, 0.0);
        let gap = |i: usize| (7..9).contains(&(i % 16)) && (7..9).contains(&(i / 16));
        let keep: Vec<usize> = (0..sheet.points.len()).filter(|&i| !gap(i)).collect();
        for list in [&mut sheet.points, &mut sheet.normals, &mut sheet.colors] {
            *list = keep.iter().map(|&i| list[i]).collect();
        }
        let field = MeshField::new(vec![Vec3::ZERO; 3], Vec::new(), 1, 0.0);
        let measured = ObservedState {
            noise: None,
            parts: vec![sheet],
            views_with_depth: 1,
            views: 1,
            stride: 1,
        };
        let config = |close_holes| ReconstructionConfig {
            surface: SurfaceSource::Measured,
            close_holes,
            ..ReconstructionConfig::preset(crate::fit::preset::Preset::Tiny)
        };
        let (open, open_stats) = remesh(&field, Some(&measured), None, State::Start, &config(0));
        let (closed, stats) = remesh(&field, Some(&measured), None, State::Start, &config(12));
        let (open_edges, edges) = (edge_counts(&open.faces), edge_counts(&closed.faces));
        assert_eq!(open_stats.holes.closed, 0);
        // Two loops: the gap's, closed, and the sheet's rim (longer than 12 edges), left open.
        assert_eq!(
            (stats.holes.loops, stats.holes.closed),
            (2, 1),
            "{:?}",
            stats.holes
        );
        assert!(
            edges.boundary < open_edges.boundary,
            "{edges:?} vs {open_edges:?}"
        );
        assert!(edges.boundary > 12, "{edges:?}");
        assert_eq!(edges.non_manifold, 0);
        assert_eq!(closed.faces.len(), open.faces.len() + stats.holes.faces);
    }

    #[test]
    fn with_no_views_to_check_fills_a_loop_stays_open_past_the_unchecked_limit() {
        let field = MeshField::new(vec![Vec3::ZERO; 3], Vec::new(), 1, 0.0);
        let measured = ObservedState {
            noise: None,
            parts: vec![square(48, 0.0)],
            views_with_depth: 1,
            views: 1,
            stride: 1,
        };
        let config = ReconstructionConfig {
            surface: SurfaceSource::Measured,
            close_holes: MAX_HOLE_EDGES,
            ..ReconstructionConfig::preset(crate::fit::preset::Preset::Tiny)
        };
        let (sheet, stats) = remesh(&field, Some(&measured), None, State::Start, &config);
        let rim = edge_counts(&sheet.faces).boundary;
        assert!(rim > UNCHECKED_HOLE_EDGES, "{rim}");
        assert_eq!((stats.holes.loops, stats.holes.closed), (1, 0));
    }
}
