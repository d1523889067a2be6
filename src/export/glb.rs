//! [`ArticulatedObject`] → binary glTF 2.0 (GLB): a node per link in the joint tree, an animation
//! from the start to the end configuration, and each joint's data in its child node's `extras`.
//!
//! - Node hierarchy = link tree: a child link's node sits under its parent's with the joint frame
//!   (origin · motion(start value)) as its translation and rotation, so a viewer that ignores the
//!   animation shows the start state. Mesh vertices are in the link frame; for a fitted twin the
//!   link frame is the joint frame, on the axis, so the animated rotation turns the part about it.
//! - One glTF mesh per link, one primitive per [`RenderMesh`]: POSITION (with bounds), unit NORMAL,
//!   TEXCOORD_0 when textured, COLOR_0 (linear RGB) when the mesh has vertex colours, u32 indices.
//!   Vertex colours carry the colour then, so the material's factor becomes white (glTF multiplies).
//! - Animation `start_to_end`, 2 s: revolute/continuous joints as rotation keyframes at most 30°
//!   apart (glTF slerps, which would take the short way round past 180°), prismatic ones as two
//!   translation keyframes. Mimic joints follow through [`ArticulatedObject::apply_mimic`].
//! - `extras.joint` on a child node (`super::extras`): name, type, axis (joint frame), origin (xyz, rpy in the parent
//!   frame), limits and the start/end values, in URDF units (radians, metres).
//! - `extras.collision` on a link's node: its collision meshes (a twin's convex pieces) in the
//!   link frame, as the URDF's STLs hold them.
//!
//! Checked by the Khronos glTF validator in the tests (`tests/native/export.rs`).

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Affine3A, Quat, Vec3};
use gltf::json::{self, validation::Checked::Valid, validation::USize64};

use crate::data::{DataError, PngPixels, RgbaImage, encode_png};
use crate::object::{ArticulatedObject, JointKind, Material, RenderMesh};

/// Length of the start → end animation (s).
pub(crate) const ANIMATION_SECONDS: f32 = 2.0;
/// Largest rotation between two keyframes (rad).
const MAX_KEYFRAME_STEP: f32 = std::f32::consts::PI / 6.0;

/// Writes `obj` as GLB posed at `start` (one value per joint, radians / metres), animated to `end`.
/// `file` names the output in errors (a mesh index past its vertices, a non-finite vertex).
pub fn write_glb(
    obj: &ArticulatedObject,
    start: &[f32],
    end: &[f32],
    file: &str,
) -> Result<Vec<u8>, DataError> {
    super::ensure_exportable(obj, &[start, end], file)?;
    let start = obj.apply_mimic(start);
    let end = obj.apply_mimic(end);
    let mut b = Builder::default();
    b.root.asset.generator = Some(format!("artmesh {}", env!("CARGO_PKG_VERSION")));

    if obj.links.is_empty() {
        return Err(DataError::file(file, "the object has no links to export"));
    }
    let mut nodes = vec![None; obj.links.len()];
    let root = obj.root.min(obj.links.len() - 1);
    let root_node = b.link_node(obj, root, Affine3A::IDENTITY, None, file)?;
    nodes[root] = Some(root_node);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for j in obj.joint_order() {
        let joint = &obj.joints[j];
        let Some(parent) = nodes.get(joint.parent).copied().flatten() else {
            continue;
        };
        let local = joint.origin * joint.motion(start[j]);
        let extras = super::extras::joint(obj, j, start[j], end[j]);
        let node = b.link_node(obj, joint.child, local, Some(extras), file)?;
        b.root.nodes[parent.value()]
            .children
            .get_or_insert_with(Vec::new)
            .push(node);
        nodes[joint.child] = Some(node);
        if let Some((path, keys)) = keyframes(joint, start[j], end[j]) {
            let input = b.times(keys.len());
            let output = b.floats(&keys.concat(), keys[0].len(), None, false);
            let sampler = json::Index::push(
                &mut samplers,
                json::animation::Sampler {
                    input,
                    output,
                    interpolation: Valid(json::animation::Interpolation::Linear),
                    extensions: None,
                    extras: None,
                },
            );
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    node,
                    path: Valid(path),
                    extensions: None,
                    extras: None,
                },
                extensions: None,
                extras: None,
            });
        }
    }
    if !channels.is_empty() {
        b.root.push(json::Animation {
            name: Some("start_to_end".into()),
            channels,
            samplers,
            extensions: None,
            extras: None,
        });
    }
    let scene = b.root.push(json::Scene {
        name: Some(obj.name.clone()),
        nodes: vec![root_node],
        extensions: None,
        extras: None,
    });
    b.root.scene = Some(scene);
    b.finish(file)
}

/// Rotation or translation keyframes of a joint's node from `start` to `end`; `None` when it does
/// not move.
fn keyframes(
    joint: &crate::object::Joint,
    start: f32,
    end: f32,
) -> Option<(json::animation::Property, Vec<Vec<f32>>)> {
    if !joint.kind.is_movable() || (end - start).abs() < 1e-9 || !(end - start).is_finite() {
        return None;
    }
    let steps = match joint.kind {
        JointKind::Prismatic => 1,
        _ => ((end - start).abs() / MAX_KEYFRAME_STEP).ceil().max(1.0) as usize,
    };
    let values = (0..=steps).map(|i| start + (end - start) * i as f32 / steps as f32);
    let poses = values.map(|q| {
        let (_, r, t) = (joint.origin * joint.motion(q)).to_scale_rotation_translation();
        (r.normalize(), t)
    });
    match joint.kind {
        JointKind::Prismatic => Some((
            json::animation::Property::Translation,
            poses.map(|(_, t)| t.to_array().to_vec()).collect(),
        )),
        _ => {
            // Keep neighbouring quaternions in one hemisphere so each slerp takes the short arc.
            let mut previous = Quat::IDENTITY;
            let keys = poses
                .enumerate()
                .map(|(i, (r, _))| {
                    let r = if i > 0 && previous.dot(r) < 0.0 {
                        -r
                    } else {
                        r
                    };
                    previous = r;
                    r.to_array().to_vec()
                })
                .collect();
            Some((json::animation::Property::Rotation, keys))
        }
    }
}

/// The JSON document and binary chunk under construction.
#[derive(Default)]
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
    /// Keyframe-time accessors by keyframe count.
    times: HashMap<usize, json::Index<json::Accessor>>,
    /// Materials as written (factor and texture after the vertex-colour rule).
    materials: Vec<(Material, json::Index<json::Material>)>,
    /// Textures by image.
    textures: HashMap<*const RgbaImage, json::Index<json::Texture>>,
}

impl Builder {
    /// A node for `link` with its meshes, at `local` in its parent.
    fn link_node(
        &mut self,
        obj: &ArticulatedObject,
        link: usize,
        local: Affine3A,
        extras: Option<serde_json::Value>,
        file: &str,
    ) -> Result<json::Index<json::Node>, DataError> {
        let name = obj.links[link].name.clone();
        let mut primitives = Vec::new();
        for (k, mesh) in obj.link_meshes(link).iter().enumerate() {
            if let Some(p) = self.primitive(mesh, &format!("link {name} mesh {k}"), file)? {
                primitives.push(p);
            }
        }
        let mesh = (!primitives.is_empty()).then(|| {
            self.root.push(json::Mesh {
                name: Some(name.clone()),
                primitives,
                weights: None,
                extensions: None,
                extras: None,
            })
        });
        let (_, rotation, translation) = local.to_scale_rotation_translation();
        let rotation = rotation.normalize();
        Ok(self.root.push(json::Node {
            name: Some(name),
            mesh,
            translation: (translation != Vec3::ZERO).then(|| translation.to_array()),
            rotation: (rotation != Quat::IDENTITY)
                .then(|| json::scene::UnitQuaternion(rotation.to_array())),
            extras: super::extras::with_collision(extras, obj, link).and_then(raw),
            ..Default::default()
        }))
    }

    /// One primitive of `mesh`; `None` for an empty mesh.
    fn primitive(
        &mut self,
        mesh: &RenderMesh,
        what: &str,
        file: &str,
    ) -> Result<Option<json::mesh::Primitive>, DataError> {
        let n = mesh.positions.len();
        if n == 0 || mesh.indices.is_empty() {
            return Ok(None);
        }
        if let Some(t) = mesh
            .indices
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(DataError::field(
                file,
                what,
                format!("triangle {t:?} indexes past the mesh's {n} vertices"),
            ));
        }
        if mesh.positions.iter().any(|p| !p.is_finite()) {
            return Err(DataError::field(
                file,
                what,
                "a vertex position is not finite",
            ));
        }
        let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
        let normals: Vec<f32> = (0..n)
            .flat_map(|i| {
                // The validator requires unit normals; a degenerate corner gets +z.
                let v = mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO);
                let v = if v.is_finite() {
                    v.normalize_or_zero()
                } else {
                    Vec3::ZERO
                };
                if v == Vec3::ZERO { Vec3::Z } else { v }.to_array()
            })
            .collect();
        let target = Some(json::buffer::Target::ArrayBuffer);
        let mut attributes = std::collections::BTreeMap::new();
        attributes.insert(
            Valid(json::mesh::Semantic::Positions),
            self.floats(&positions, 3, target, true),
        );
        attributes.insert(
            Valid(json::mesh::Semantic::Normals),
            self.floats(&normals, 3, target, false),
        );
        let textured =
            mesh.material.texture.is_some() && mesh.uvs.as_ref().is_some_and(|u| u.len() == n);
        if textured && let Some(uvs) = &mesh.uvs {
            let uvs: Vec<f32> = uvs
                .iter()
                .flat_map(|t| {
                    if t.is_finite() {
                        t.to_array()
                    } else {
                        [0.0; 2]
                    }
                })
                .collect();
            attributes.insert(
                Valid(json::mesh::Semantic::TexCoords(0)),
                self.floats(&uvs, 2, target, false),
            );
        }
        let colors = mesh.colors.as_ref().filter(|c| c.len() == n);
        if let Some(colors) = colors {
            let flat: Vec<f32> = colors
                .iter()
                .flat_map(|c| {
                    c.map(|v| {
                        if v.is_finite() {
                            v.clamp(0.0, 1.0)
                        } else {
                            0.0
                        }
                    })
                })
                .collect();
            attributes.insert(
                Valid(json::mesh::Semantic::Colors(0)),
                self.floats(&flat, 3, target, false),
            );
        }
        let flat: Vec<u32> = mesh.indices.iter().flatten().copied().collect();
        let view = self.view(
            bytemuck::cast_slice(&flat),
            Some(json::buffer::Target::ElementArrayBuffer),
        );
        let indices = self.accessor(
            view,
            flat.len(),
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
        );
        let material = self.material(&mesh.material, colors.is_some(), textured, file)?;
        Ok(Some(json::mesh::Primitive {
            attributes,
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
            extensions: None,
            extras: None,
        }))
    }

    /// The material for `m` (shared by equal materials).
    fn material(
        &mut self,
        m: &Material,
        vertex_colors: bool,
        textured: bool,
        file: &str,
    ) -> Result<json::Index<json::Material>, DataError> {
        let mut factor = m.base_color.map(|v| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                1.0
            }
        });
        if vertex_colors {
            factor = [1.0, 1.0, 1.0, factor[3]];
        }
        // Materials that write the same JSON are one (the texture compared by image).
        let emitted = Material {
            base_color: factor,
            texture: m.texture.clone().filter(|_| textured),
            ..m.clone()
        };
        if let Some((_, index)) = self.materials.iter().find(|(other, _)| *other == emitted) {
            return Ok(*index);
        }
        let texture = match (&m.texture, textured) {
            (Some(image), true) => Some(json::texture::Info {
                index: self.texture(image, file)?,
                tex_coord: 0,
                extensions: None,
                extras: None,
            }),
            _ => None,
        };
        let index = self.root.push(json::Material {
            name: m.name.clone(),
            alpha_cutoff: None,
            alpha_mode: Valid(if factor[3] < 1.0 {
                json::material::AlphaMode::Blend
            } else {
                json::material::AlphaMode::Opaque
            }),
            // Fitted surfaces are open sheets whose winding is not reliable.
            double_sided: true,
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(factor),
                base_color_texture: texture,
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.9),
                metallic_roughness_texture: None,
                extensions: None,
                extras: None,
            },
            normal_texture: None,
            occlusion_texture: None,
            emissive_texture: None,
            emissive_factor: json::material::EmissiveFactor([0.0; 3]),
            extensions: None,
            extras: None,
        });
        self.materials.push((emitted, index));
        Ok(index)
    }

    /// An embedded PNG texture for `image` (once per image).
    fn texture(
        &mut self,
        image: &Arc<RgbaImage>,
        file: &str,
    ) -> Result<json::Index<json::Texture>, DataError> {
        let key = Arc::as_ptr(image);
        if let Some(t) = self.textures.get(&key) {
            return Ok(*t);
        }
        let png = encode_png(
            file,
            image.width,
            image.height,
            PngPixels::Rgba8(&image.pixels),
        )?;
        let view = self.view(&png, None);
        let source = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".into())),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        let texture = self.root.push(json::Texture {
            name: None,
            sampler: None,
            source,
            extensions: None,
            extras: None,
        });
        self.textures.insert(key, texture);
        Ok(texture)
    }

    /// Appends `bytes` to the binary chunk (4-byte aligned) as a buffer view.
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: None,
        })
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        ty: json::accessor::Type,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = bounds.map_or((None, None), |(lo, hi)| {
            (Some(serde_json::json!(lo)), Some(serde_json::json!(hi)))
        });
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(ty),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: None,
        })
    }

    /// A float accessor of `width`-component elements (`bounds`: with per-component min/max).
    fn floats(
        &mut self,
        data: &[f32],
        width: usize,
        target: Option<json::buffer::Target>,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let ty = match width {
            1 => json::accessor::Type::Scalar,
            2 => json::accessor::Type::Vec2,
            3 => json::accessor::Type::Vec3,
            _ => json::accessor::Type::Vec4,
        };
        let bounds = bounds.then(|| {
            let mut lo = vec![f32::INFINITY; width];
            let mut hi = vec![f32::NEG_INFINITY; width];
            for e in data.chunks_exact(width) {
                for c in 0..width {
                    lo[c] = lo[c].min(e[c]);
                    hi[c] = hi[c].max(e[c]);
                }
            }
            (lo, hi)
        });
        let view = self.view(bytemuck::cast_slice(data), target);
        self.accessor(
            view,
            data.len() / width,
            json::accessor::ComponentType::F32,
            ty,
            bounds,
        )
    }

    /// Keyframe times 0 ..= [`ANIMATION_SECONDS`] for `count` keyframes (shared).
    fn times(&mut self, count: usize) -> json::Index<json::Accessor> {
        if let Some(a) = self.times.get(&count) {
            return *a;
        }
        let last = count.saturating_sub(1).max(1) as f32;
        let t: Vec<f32> = (0..count)
            .map(|i| ANIMATION_SECONDS * i as f32 / last)
            .collect();
        let a = self.floats(&t, 1, None, true);
        self.times.insert(count, a);
        a
    }

    /// The GLB bytes.
    fn finish(mut self, file: &str) -> Result<Vec<u8>, DataError> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        if !self.bin.is_empty() {
            self.root.push(json::Buffer {
                byte_length: USize64::from(self.bin.len()),
                name: None,
                uri: None,
                extensions: None,
                extras: None,
            });
        }
        let mut text = json::serialize::to_vec(&self.root)
            .map_err(|e| DataError::file(file, format!("could not encode the glTF JSON: {e}")))?;
        // The JSON chunk is padded with spaces (GLB spec), the binary one with zeros.
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0, // to_vec computes it
            },
            json: text.into(),
            bin: (!self.bin.is_empty()).then(|| self.bin.into()),
        };
        glb.to_vec()
            .map_err(|e| DataError::file(file, format!("could not write the GLB: {e}")))
    }
}

/// A JSON value as glTF `extras` (`None` only if it could not be written, which a `Value` cannot).
fn raw(value: serde_json::Value) -> Option<Box<json::extras::RawValue>> {
    serde_json::value::to_raw_value(&value).ok()
}
