//! Exports of a fitted twin that simulators and viewers load as they are (docs/design.md §8).
//!
//! - [`twin`]: the fit (or a ground truth) as an [`ArticulatedObject`](crate::object::ArticulatedObject):
//!   base link = part 0, one link and one revolute/prismatic joint per movable part.
//! - [`urdf`]: URDF + meshes (OBJ visuals with colours, STL collisions, inertials from the mesh
//!   volume at [`inertia::DENSITY`]), limits on every joint.
//! - [`glb`]: binary glTF with the link tree as nodes, vertex colours, a start → end animation and
//!   the joints in `extras`.
//! - [`joints`]: `joints.json`, the fitted joints as records with their names, limits and evidence.
//! - [`archive`]: everything as one zip whose paths cannot leave the folder it is unpacked in.
//! - [`folder`]: all of a fit's files (report, joints, part meshes, exports) for the CLI's fit
//!   folder and the page's downloads.
//!
//! Like the rest of the core, bytes in and bytes out: the browser app downloads what these return.

pub mod archive;
pub mod collision;
pub(crate) mod extras;
pub mod finite;
pub mod folder;
pub mod glb;
pub mod inertia;
pub mod joints;
pub mod twin;
pub mod urdf;

pub use archive::write_zip;
pub use finite::ensure_exportable;
pub use folder::{FitFolder, FolderError, REPORT_FILE};
pub use glb::write_glb;
pub use joints::{GeometryRecord, JointRecord, joint_records};
pub use twin::{NoStartState, Twin, TwinPart};
pub use urdf::write_urdf;

use crate::data::{DataError, FileSet};
use crate::object::{ArticulatedObject, JointKind};

/// The URDF's path in a fit folder (its meshes go to `urdf/meshes/`).
pub const URDF_FILE: &str = "urdf/twin.urdf";
/// The GLB's path in a fit folder.
pub const GLB_FILE: &str = "twin.glb";
/// The archive's path in a fit folder.
pub const ZIP_FILE: &str = "twin.zip";
/// The joint list's path in a fit folder (and in the archive).
pub const JOINTS_FILE: &str = "joints.json";

/// Every export of one twin.
#[derive(Debug, Clone, PartialEq)]
pub struct TwinFiles {
    /// `twin.urdf` and `meshes/…`, relative to the URDF's folder.
    pub urdf: FileSet,
    pub glb: Vec<u8>,
    /// URDF + meshes + `joints.json` + `twin.glb` under one folder named after the object.
    pub zip: Vec<u8>,
}

impl TwinFiles {
    /// The files as a fit folder holds them ([`URDF_FILE`] and its meshes, [`GLB_FILE`], [`ZIP_FILE`]).
    pub(crate) fn into_fit_folder(self) -> FileSet {
        let folder = URDF_FILE.rsplit_once('/').map_or("", |(f, _)| f);
        let mut files: FileSet = self
            .urdf
            .into_iter()
            .map(|(path, bytes)| (format!("{folder}/{path}"), bytes))
            .collect();
        files.insert(GLB_FILE.into(), self.glb);
        files.insert(ZIP_FILE.into(), self.zip);
        files
    }
}

/// Writes the URDF, the GLB (start = every joint at 0, animated to `end`) and the archive of
/// `object`; `joints_json` goes into the archive as [`JOINTS_FILE`].
pub fn export_twin(
    object: &ArticulatedObject,
    end: &[f32],
    joints_json: &[u8],
) -> Result<TwinFiles, DataError> {
    let urdf_name = URDF_FILE.rsplit('/').next().unwrap_or(URDF_FILE);
    let urdf = write_urdf(object, urdf_name)?;
    let glb = write_glb(object, &vec![0.0; object.joints.len()], end, GLB_FILE)?;
    let mut all = urdf.clone();
    all.insert(JOINTS_FILE.into(), joints_json.to_vec());
    all.insert(GLB_FILE.into(), glb.clone());
    let zip = write_zip(&all, &urdf::file_stem(&object.name), ZIP_FILE)?;
    Ok(TwinFiles { urdf, glb, zip })
}

/// The end-state value of each of `object`'s joints (radians / metres) from a fit's `joints.json`
/// (records with `joint`, `type` and `motion` in degrees or metres); joints it does not list stay at 0.
/// Errors name `file` and the field at fault.
pub fn end_configuration(
    object: &ArticulatedObject,
    joints_json: &[u8],
    file: &str,
) -> Result<Vec<f32>, DataError> {
    let records: serde_json::Value = serde_json::from_slice(joints_json)
        .map_err(|e| DataError::file(file, format!("not valid JSON: {e}")))?;
    let records = records
        .as_array()
        .ok_or_else(|| DataError::file(file, "expected a list of joint records"))?;
    let mut end = vec![0.0; object.joints.len()];
    for (i, record) in records.iter().enumerate() {
        let field = |name: &str| format!("[{i}].{name}");
        let name = record["joint"].as_str().ok_or_else(|| {
            DataError::field(file, field("joint"), "expected the joint's name (text)")
        })?;
        let j = object.joint_index(name).ok_or_else(|| {
            DataError::field(
                file,
                field("joint"),
                format!("no joint named {name:?} in the URDF"),
            )
        })?;
        // A finite f64 past f32's range (1e300) would become infinity here.
        let motion = record["motion"]
            .as_f64()
            .filter(|m| m.abs() <= f64::from(f32::MAX))
            .ok_or_else(|| {
                DataError::field(
                    file,
                    field("motion"),
                    format!(
                        "expected a finite number (degrees or metres), found {}",
                        record["motion"]
                    ),
                )
            })? as f32;
        let kind = record["type"].as_str().unwrap_or_default();
        end[j] = match (kind, object.joints[j].kind) {
            ("revolute", JointKind::Revolute | JointKind::Continuous) => motion.to_radians(),
            ("prismatic", JointKind::Prismatic) => motion,
            (_, JointKind::Fixed) if motion == 0.0 => 0.0,
            _ => {
                return Err(DataError::field(
                    file,
                    field("type"),
                    format!(
                        "expected the URDF joint's type ({:?}), found {kind:?}",
                        object.joints[j].kind
                    ),
                ));
            }
        };
    }
    Ok(end)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{GtJoint, JointKind as GtKind, TriMesh};
    use glam::Vec3;

    fn twin() -> Twin {
        // A tetrahedron per part: closed, with volume (a flat part would get a box collision).
        let part = |z: f32| TwinPart {
            mesh: TriMesh {
                positions: vec![
                    Vec3::new(0.0, 0.0, z),
                    Vec3::new(1.0, 0.0, z),
                    Vec3::new(0.0, 1.0, z),
                    Vec3::new(0.0, 0.0, z + 1.0),
                ],
                triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
            },
            colors: None,
        };
        let joint = |kind, end| GtJoint {
            kind,
            origin: Vec3::new(0.5, 0.0, 0.0),
            direction: Vec3::Z * 2.0,
            start: 10.0,
            end,
        };
        Twin {
            name: "t".into(),
            parts: vec![part(0.0), part(1.0), part(2.0)],
            joints: vec![joint(GtKind::Revolute, 40.0), joint(GtKind::Prismatic, 9.8)],
        }
    }

    #[test]
    fn end_configuration_reads_joints_json_and_names_bad_fields() {
        let object = twin().object();
        assert_eq!(
            object.joints[0].limit.map(|l| (l.lower, l.upper)),
            Some((0.0, 30f32.to_radians()))
        );
        assert_eq!(
            object.joints[1].limit.map(|l| (l.lower, l.upper)),
            Some((-0.19999981, 0.0))
        );
        let good = br#"[{"joint": "joint_2", "type": "prismatic", "motion": -0.2},
                        {"joint": "joint_1", "type": "revolute", "motion": 30}]"#;
        let end = end_configuration(&object, good, "j.json").unwrap();
        assert_eq!(end, vec![30f32.to_radians(), -0.2]);
        assert_eq!(twin().end_configuration()[0], end[0]);
        for (bad, field) in [
            (&br#"{"joint": 1}"#[..], None),
            (br#"[{"type": "revolute", "motion": 1}]"#, Some("[0].joint")),
            (
                br#"[{"joint": "door", "type": "revolute", "motion": 1}]"#,
                Some("[0].joint"),
            ),
            (
                br#"[{"joint": "joint_1", "type": "revolute"}]"#,
                Some("[0].motion"),
            ),
            (
                br#"[{"joint": "joint_1", "type": "prismatic", "motion": 1}]"#,
                Some("[0].type"),
            ),
            (b"not json", None),
        ] {
            let e = end_configuration(&object, bad, "j.json").unwrap_err();
            assert_eq!(
                (e.file.as_str(), e.field.as_deref()),
                ("j.json", field),
                "{e}"
            );
        }
    }

    #[test]
    fn fit_folder_layout() {
        let t = twin();
        let files = export_twin(&t.object(), &t.end_configuration(), b"[]").unwrap();
        let folder = files.into_fit_folder();
        for f in [
            URDF_FILE,
            GLB_FILE,
            ZIP_FILE,
            "urdf/meshes/part_1.obj",
            "urdf/meshes/part_2_collision_0.stl",
        ] {
            assert!(folder.contains_key(f), "{f}: {:?}", folder.keys());
        }
        let back = ArticulatedObject::from_urdf(URDF_FILE, &folder).unwrap();
        assert_eq!(back.joints.len(), 2);
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    }
}
