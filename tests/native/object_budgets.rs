//! Object imports that a naive reader would let exhaust memory or time (issue 26's examples and a
//! variant of each): textures named hundreds of times decode once, node graphs that multiply and
//! objects that repeat one mesh past the triangle budget are refused, each within seconds.

use std::sync::Arc;
use std::time::Instant;

use artmesh::data::FileSet;
use artmesh::fixtures::hostile;
use artmesh::object::{ArticulatedObject, Geometry, RenderMesh, load_mesh};

/// Runs `read`, checking it takes under the 20 s the issue allows.
fn timed<T>(what: &str, read: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = read();
    let secs = start.elapsed().as_secs_f64();
    assert!(secs < 20.0, "{what} took {secs:.1} s");
    out
}

fn mesh(path: &str, files: &FileSet) -> Result<Vec<RenderMesh>, String> {
    load_mesh(path, files, &mut Vec::new()).map_err(|e| e.to_string())
}

/// Every mesh's texture is one shared decoding.
fn all_share_one_texture(meshes: &[RenderMesh]) {
    let first = meshes[0].material.texture.clone().expect("textured");
    for m in meshes {
        let t = m.material.texture.as_ref().expect("textured");
        assert!(Arc::ptr_eq(t, &first), "a texture was decoded twice");
    }
}

#[test]
fn an_mtl_naming_one_texture_600_times_decodes_it_once() {
    let files = hostile::obj_materials_sharing_one_texture(600, 2048);
    let meshes = timed("600 materials", || mesh("m/shared.obj", &files)).unwrap();
    assert_eq!(meshes.len(), 600);
    all_share_one_texture(&meshes);
    assert_eq!(meshes[0].material.texture.as_ref().unwrap().width, 2048);
}

#[test]
fn a_gltf_whose_600_images_name_one_file_decodes_it_once() {
    let files = hostile::gltf_images_sharing_one_file(600, 2048);
    let meshes = timed("600 images", || mesh("g/images.gltf", &files)).unwrap();
    assert_eq!(meshes.len(), 600);
    all_share_one_texture(&meshes);
}

#[test]
fn urdf_materials_naming_one_texture_share_its_decoding() {
    let files = hostile::urdf_materials_sharing_one_texture(600, 2048);
    let object = timed("600 URDF materials", || {
        ArticulatedObject::from_urdf("r/robot.urdf", &files)
    })
    .unwrap();
    let textures: Vec<_> = object
        .links
        .iter()
        .map(|l| {
            l.visuals[0]
                .material
                .as_ref()
                .unwrap()
                .texture
                .clone()
                .unwrap()
        })
        .collect();
    assert_eq!(textures.len(), 600);
    assert!(textures.iter().all(|t| Arc::ptr_eq(t, &textures[0])));
}

#[test]
fn a_texture_claiming_gigapixels_is_skipped_with_a_warning() {
    let mut files = hostile::obj_materials_sharing_one_texture(3, 4);
    files.insert("m/tex.png".into(), hostile::png_claiming(100_000));
    let mut warnings = Vec::new();
    let meshes = timed("a 10-gigapixel header", || {
        load_mesh("m/shared.obj", &files, &mut warnings)
    })
    .unwrap();
    assert!(meshes.iter().all(|m| m.material.texture.is_none()));
    assert!(
        warnings.iter().any(|w| w.contains("10000000000 pixels")),
        "{warnings:?}"
    );
}

#[test]
fn gltf_nodes_that_multiply_are_refused() {
    // 2⁴⁰ instances (the example) and 3²⁰ (a variant).
    for (depth, fanout) in [(40, 2), (20, 3)] {
        let files = hostile::gltf_multiplying_nodes(depth, fanout);
        let e = timed("multiplying nodes", || mesh("g/chain.gltf", &files)).unwrap_err();
        assert!(e.contains("g/chain.gltf"), "{e}");
        assert!(e.contains("more than 200000 node instances"), "{e}");
    }
}

#[test]
fn a_scene_listing_one_node_many_times_reads_or_is_refused() {
    // 100 000 listings (the example, which hung the capture) is a real if odd scene.
    let files = hostile::gltf_scene_listing_one_node(100_000);
    let meshes = timed("100 000 listings", || mesh("g/listed.gltf", &files)).unwrap();
    assert_eq!(meshes.len(), 100_000);
    let files = hostile::gltf_scene_listing_one_node(300_000);
    let e = timed("300 000 listings", || mesh("g/listed.gltf", &files)).unwrap_err();
    assert!(e.contains("more than 200000 node instances"), "{e}");
}

#[test]
fn links_repeating_one_mesh_past_the_triangle_budget_are_refused() {
    // 2000 links × 20 000 triangles = 40 M triangles from a 1 MB STL.
    let files = hostile::urdf_links_sharing_one_mesh(2000, 20_000);
    let e = timed("2000 links", || {
        ArticulatedObject::from_urdf("r/robot.urdf", &files)
    })
    .unwrap_err();
    assert_eq!(e.file, "r/robot.urdf");
    assert!(e.message.contains("more than 20000000 triangles"), "{e}");
    // Below the budget the same mesh is shared, not copied.
    let files = hostile::urdf_links_sharing_one_mesh(50, 20_000);
    let object = ArticulatedObject::from_urdf("r/robot.urdf", &files).unwrap();
    let meshes: Vec<_> = object
        .links
        .iter()
        .map(|l| match &l.visuals[0].geometry {
            Geometry::Mesh { meshes, .. } => meshes.clone(),
            other => panic!("expected a mesh, got {other:?}"),
        })
        .collect();
    assert!(meshes.iter().all(|m| Arc::ptr_eq(m, &meshes[0])));
}
