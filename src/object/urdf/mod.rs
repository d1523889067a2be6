//! URDF (XML) → [`ArticulatedObject`].
//!
//! Reads `<robot>` with its `<material>`, `<link>` (visual/collision with origin, geometry, material) and
//! `<joint>` (type, parent, child, origin, axis, limit, mimic) elements; every other element or attribute
//! (`<inertial>`, `<gazebo>`, `<transmission>`, `<dynamics>`, `<contact>`, `group=`, ...) is ignored, as URDF
//! readers do. Errors name the file, an element path such as `robot/joint[name=door_hinge]/limit@lower` and
//! its line, and what was expected.
//!
//! Numbers: vectors are whitespace-separated, as the URDF spec says. The one exception is mesh `scale`, where
//! commas between the numbers (`scale="1, 1, 1"`) are accepted because habitat-sim's assets write them that way
//! throughout and habitat's reader takes them; elsewhere (`origin@xyz="0.01, -0.33, 0"`) a comma is an error.

mod attributes;
mod joints;
mod links;
mod reader;
mod resolve;

use std::collections::HashMap;

use crate::data::{DataError, FileSource};

use super::mesh_io::Textures;
use super::{ArticulatedObject, Joint, Link};
use reader::{Reader, children};

/// Reads the URDF `urdf_path` of `files` and every mesh and texture it refers to.
pub(super) fn read_urdf(
    urdf_path: &str,
    files: &dyn FileSource,
) -> Result<ArticulatedObject, DataError> {
    let bytes = files
        .file(urdf_path)
        .ok_or_else(|| DataError::file(urdf_path, "URDF file not found in the dataset"))?;
    let text = std::str::from_utf8(bytes)
        .map_err(|e| DataError::file(urdf_path, format!("URDF is not valid UTF-8: {e}")))?;
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let at = e.pos();
        DataError::file(
            urdf_path,
            format!(
                "URDF is not well-formed XML at line {}, column {} ({e}): expected an XML document whose root element is <robot>",
                at.row, at.col
            ),
        )
    })?;
    let robot = doc.root_element();
    let mut cx = Reader {
        file: urdf_path,
        doc: &doc,
        files,
        folder: match urdf_path.rfind('/') {
            Some(i) => &urdf_path[..=i],
            None => "",
        },
        packages: None,
        meshes: HashMap::new(),
        textures: Textures::default(),
        triangles: 0,
        materials: HashMap::new(),
        warnings: Vec::new(),
    };
    if robot.tag_name().name() != "robot" {
        return Err(cx.err(
            robot,
            robot.tag_name().name(),
            None,
            "expected the root element <robot>",
        ));
    }
    let name = robot.attribute("name").unwrap_or_default().to_string();

    // Robot-level materials first: visuals may refer to materials defined after them.
    for node in children(robot, "material") {
        let mname = cx.required(node, "robot/material", "name")?.to_string();
        let path = format!("robot/material[name={mname}]");
        if let Some(m) = cx.material_body(node, &path, &mname)? {
            cx.materials.insert(mname, m);
        }
    }

    let mut links = Vec::new();
    let mut link_index: HashMap<String, usize> = HashMap::new();
    for node in children(robot, "link") {
        let lname = cx.required(node, "robot/link", "name")?.to_string();
        let path = format!("robot/link[name={lname}]");
        if link_index.contains_key(&lname) {
            return Err(cx.err(node, &path, Some("name"), "duplicate link name"));
        }
        let mut visuals = Vec::new();
        for (i, v) in children(node, "visual").enumerate() {
            visuals.push(cx.visual(v, &format!("{path}/visual[{i}]"), true)?);
        }
        let mut collisions = Vec::new();
        for (i, v) in children(node, "collision").enumerate() {
            collisions.push(cx.visual(v, &format!("{path}/collision[{i}]"), false)?);
        }
        link_index.insert(lname.clone(), links.len());
        links.push(Link {
            name: lname,
            visuals,
            collisions,
        });
    }
    if links.is_empty() {
        return Err(cx.err(robot, "robot", None, "the robot has no <link>"));
    }

    let mut joints = Vec::new();
    let mut joint_nodes = Vec::new();
    for node in children(robot, "joint") {
        let joint = cx.joint(node, &link_index)?;
        if joints.iter().any(|j: &Joint| j.name == joint.name) {
            let path = format!("robot/joint[name={}]", joint.name);
            return Err(cx.err(node, &path, Some("name"), "duplicate joint name"));
        }
        joints.push(joint);
        joint_nodes.push(node);
    }
    cx.resolve_mimics(&mut joints, &joint_nodes)?;
    let root = cx.check_tree(robot, &links, &joints, &joint_nodes)?;

    Ok(ArticulatedObject {
        name,
        links,
        joints,
        root,
        warnings: cx.warnings,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::data::FileSet;

    fn files(urdf: &str) -> FileSet {
        let mut f = FileSet::new();
        f.insert("r/robot.urdf".into(), urdf.as_bytes().to_vec());
        f
    }

    #[test]
    fn object_urdf_rpy_is_fixed_axis_xyz() {
        let urdf = r#"<robot name="t"><link name="a"/><link name="b"/>
            <joint name="j" type="fixed"><parent link="a"/><child link="b"/>
            <origin xyz="1 2 3" rpy="0 0 1.5707963"/></joint></robot>"#;
        let o = read_urdf("r/robot.urdf", &files(urdf)).unwrap();
        let t = o.joints[0].origin;
        assert!((t.transform_vector3(Vec3::X) - Vec3::Y).length() < 1e-6);
        assert!((t.translation - glam::Vec3A::new(1.0, 2.0, 3.0)).length() < 1e-6);
        // Roll then pitch: rpy = (π/2, π/2, 0) maps z → x (Ry(π/2) after Rx(π/2)).
        let urdf2 = urdf.replace("0 0 1.5707963", "1.5707963 1.5707963 0");
        let o2 = read_urdf("r/robot.urdf", &files(&urdf2)).unwrap();
        let y = o2.joints[0].origin.transform_vector3(Vec3::Y);
        assert!((y - Vec3::X).length() < 1e-5, "{y}");
    }

    #[test]
    fn object_urdf_errors_carry_path_and_line() {
        let urdf = "<robot name=\"t\">\n<link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\">\n<parent link=\"a\"/><child link=\"b\"/>\n<limit lower=\"x\" upper=\"1\"/></joint></robot>";
        let e = read_urdf("r/robot.urdf", &files(urdf)).unwrap_err();
        assert_eq!(e.file, "r/robot.urdf");
        assert_eq!(
            e.field.as_deref(),
            Some("robot/joint[name=j]/limit@lower (line 5)")
        );
        assert!(e.message.contains("finite number"), "{e}");
    }

    #[test]
    fn object_urdf_structure_errors() {
        let cases = [
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"a\"/></robot>",
                "duplicate link",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/></robot>",
                "one root link",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                "need <limit",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"planar\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                "not supported",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"c\"/></joint></robot>",
                "no link named",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint><joint name=\"k\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>",
                "cycle",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><capsule/></geometry></visual></link></robot>",
                "unsupported geometry",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"file:///x.obj\"/></geometry></visual></link></robot>",
                "absolute path",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"../../x.obj\"/></geometry></visual></link></robot>",
                "leaves the dataset",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"><visual><geometry><mesh filename=\"package://nope/x.obj\"/></geometry></visual></link></robot>",
                "no package.xml",
            ),
            (
                "<robot name=\"t\"><link name=\"a\"/><link name=\"b\"/><link name=\"c\"/><joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/><mimic joint=\"k\"/></joint><joint name=\"k\" type=\"continuous\"><parent link=\"b\"/><child link=\"c\"/><mimic joint=\"j\"/></joint></robot>",
                "the mimic joints j → k → j follow each other in a cycle",
            ),
            ("<robot><link", "well-formed"),
            ("<model/>", "<robot>"),
        ];
        for (urdf, expected) in cases {
            let e = read_urdf("r/robot.urdf", &files(urdf)).unwrap_err();
            assert!(e.to_string().contains(expected), "{urdf}: {e}");
        }
    }

    #[test]
    fn object_urdf_primitives_and_materials() {
        let urdf = r#"<robot name="t">
            <material name="red"><color rgba="1 0 0 1"/></material>
            <link name="a">
              <visual><origin xyz="0 0 1"/><geometry><box size="1 2 3"/></geometry><material name="red"/></visual>
              <visual><geometry><cylinder radius="0.5" length="2"/></geometry><material name="blue"><color rgba="0 0 1 1"/></material></visual>
              <visual><geometry><sphere radius="1"/></geometry><material name="undefined"/></visual>
              <collision><geometry><box size="1 1 1"/></geometry></collision>
              <gazebo><plugin name="x"/></gazebo>
            </link></robot>"#;
        let o = read_urdf("r/robot.urdf", &files(urdf)).unwrap();
        let l = &o.links[0];
        assert_eq!(l.visuals.len(), 3);
        assert_eq!(l.collisions.len(), 1);
        assert_eq!(
            l.visuals[0].material.as_ref().unwrap().base_color,
            [1.0, 0.0, 0.0, 1.0]
        );
        assert_eq!(
            l.visuals[1].material.as_ref().unwrap().base_color,
            [0.0, 0.0, 1.0, 1.0]
        );
        assert!(l.visuals[2].material.is_none());
        assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
        let meshes = o.link_meshes(0);
        assert_eq!(meshes.len(), 3);
        assert_eq!(meshes[0].material.base_color, [1.0, 0.0, 0.0, 1.0]);
        let top = meshes[0]
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f32::MIN, f32::max);
        assert!((top - 2.5).abs() < 1e-6);
    }
}
