//! `transforms_{split}_{state}.json`: cameras and the frame list (NeRF-Blender / nerfstudio style).
//!
//! Intrinsics come from `fl_x fl_y cx cy w h` when present (nerfstudio; also allowed per frame), else from
//! `camera_angle_x` (and `camera_angle_y`) with the image size, principal point at the image centre.
//! We write both forms, so readers of either kind can use our files and our own reader needs no trigonometry.

use glam::{DMat3, DVec3, Mat4};
use serde_json::{Map, Value, json};

use super::camera::{Camera, Intrinsics};
use super::error::{DataError, Errors};
use super::frame::Frame;
use super::json::{self, Json, f32_array, f32_value, optional};
use super::paths;
use super::{Split, State};

/// Tolerance of the rigidity checks on `transform_matrix`.
const RIGID_TOLERANCE: f64 = 1e-3;

/// Intrinsics fields as written in a file (top level, or per frame to override it).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct IntrinsicsSpec {
    pub(crate) fl_x: Option<f64>,
    pub(crate) fl_y: Option<f64>,
    pub(crate) cx: Option<f64>,
    pub(crate) cy: Option<f64>,
    pub(crate) w: Option<u32>,
    pub(crate) h: Option<u32>,
    pub(crate) angle_x: Option<f64>,
    pub(crate) angle_y: Option<f64>,
}

impl IntrinsicsSpec {
    /// Reads whichever intrinsics fields `map` holds; bad ones are reported and left out.
    fn parse(
        j: Json<'_>,
        prefix: &str,
        map: &Map<String, Value>,
        errs: &mut Errors,
    ) -> IntrinsicsSpec {
        // A number that must satisfy `valid`; otherwise the error says what was `expected`.
        let checked = |key: &str, valid: fn(f64) -> bool, expected: &str, errs: &mut Errors| {
            let v = optional(map, key)?;
            let field = json::join(prefix, key);
            let x = errs.keep(j.number(&field, v))?;
            if valid(x) {
                Some(x)
            } else {
                errs.push(j.err(&field, format!("expected {expected}, found {x}")));
                None
            }
        };
        let positive = |key: &str, errs: &mut Errors| {
            checked(key, |x| x > 0.0, "a positive focal length in pixels", errs)
        };
        let angle = |key: &str, errs: &mut Errors| {
            let in_range = |x: f64| x > 0.0 && x < std::f64::consts::PI;
            checked(key, in_range, "an angle in radians in (0, π)", errs)
        };
        let any = |key: &str, errs: &mut Errors| -> Option<f64> {
            let v = optional(map, key)?;
            errs.keep(j.number(&json::join(prefix, key), v))
        };
        let size = |key: &str, errs: &mut Errors| -> Option<u32> {
            let v = optional(map, key)?;
            errs.keep(j.positive_u32(&json::join(prefix, key), v))
        };
        IntrinsicsSpec {
            fl_x: positive("fl_x", errs),
            fl_y: positive("fl_y", errs),
            cx: any("cx", errs),
            cy: any("cy", errs),
            w: size("w", errs),
            h: size("h", errs),
            angle_x: angle("camera_angle_x", errs),
            angle_y: angle("camera_angle_y", errs),
        }
    }

    /// `self` with the fields `frame` gives replaced.
    pub(crate) fn overlay(self, frame: &IntrinsicsSpec) -> IntrinsicsSpec {
        IntrinsicsSpec {
            fl_x: frame.fl_x.or(self.fl_x),
            fl_y: frame.fl_y.or(self.fl_y),
            cx: frame.cx.or(self.cx),
            cy: frame.cy.or(self.cy),
            w: frame.w.or(self.w),
            h: frame.h.or(self.h),
            angle_x: frame.angle_x.or(self.angle_x),
            angle_y: frame.angle_y.or(self.angle_y),
        }
    }

    fn has_focal(&self) -> bool {
        self.fl_x.is_some() || self.angle_x.is_some()
    }

    /// Pixel intrinsics for an image of `width` x `height` (the image's own size, so a stale `w`/`h` cannot
    /// produce inconsistent cameras; a mismatch is reported separately). Needs `fl_x` or `camera_angle_x`.
    pub(crate) fn resolve(&self, width: u32, height: u32) -> Option<Intrinsics> {
        let (w, h) = (f64::from(width), f64::from(height));
        let fx = self
            .fl_x
            .or_else(|| self.angle_x.map(|a| 0.5 * w / (0.5 * a).tan()))?;
        let fy = self
            .fl_y
            .or_else(|| self.angle_y.map(|a| 0.5 * h / (0.5 * a).tan()))
            .unwrap_or(fx);
        Some(Intrinsics {
            width,
            height,
            fx: fx as f32,
            fy: fy as f32,
            cx: self.cx.unwrap_or(0.5 * w) as f32,
            cy: self.cy.unwrap_or(0.5 * h) as f32,
        })
    }
}

/// One entry of `frames`.
#[derive(Debug, Clone)]
pub(crate) struct FrameSpec {
    /// `frames[i]`, for error fields.
    pub(crate) field: String,
    /// Cleaned dataset-relative path (extension as given).
    pub(crate) file_path: String,
    /// `None` when the matrix or another field of the frame is bad (already reported); the frame's images
    /// are still read so their problems are reported too.
    pub(crate) camera_to_world: Option<Mat4>,
    pub(crate) time: Option<f32>,
    /// Effective intrinsics fields (top level overlaid with this frame's).
    pub(crate) intrinsics: IntrinsicsSpec,
}

/// A parsed transforms file. Frames with errors are left out (their errors are recorded).
#[derive(Debug, Clone)]
pub(crate) struct TransformsSpec {
    pub(crate) frames: Vec<FrameSpec>,
}

/// Checks a row-major 4x4 camera-to-world matrix and converts it.
fn parse_matrix(j: Json<'_>, field: &str, v: &Value) -> Result<Mat4, DataError> {
    let rows = j.array(field, v)?;
    if rows.len() != 4 {
        return Err(j.err(
            field,
            format!(
                "expected a 4x4 matrix (4 rows of 4 numbers), found {} rows",
                rows.len()
            ),
        ));
    }
    let mut m = [[0.0f64; 4]; 4];
    for (r, (row, dst)) in rows.iter().zip(m.iter_mut()).enumerate() {
        *dst = j.numbers::<4>(&format!("{field}[{r}]"), row)?;
    }
    let last = m[3];
    if (0..4).any(|c| (last[c] - if c == 3 { 1.0 } else { 0.0 }).abs() > 1e-6) {
        return Err(j.err(
            field,
            format!("expected the last row to be [0, 0, 0, 1], found {last:?}"),
        ));
    }
    let r = DMat3::from_cols(
        DVec3::new(m[0][0], m[1][0], m[2][0]),
        DVec3::new(m[0][1], m[1][1], m[2][1]),
        DVec3::new(m[0][2], m[1][2], m[2][2]),
    );
    let gram = r.transpose() * r;
    let deviation = (gram - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, x| a.max(x.abs()));
    if deviation > RIGID_TOLERANCE {
        return Err(j.err(
            field,
            format!("not rigid: columns not orthonormal (max deviation {deviation:.4}); expected a rotation and a translation"),
        ));
    }
    let det = r.determinant();
    if (det - 1.0).abs() > RIGID_TOLERANCE {
        return Err(j.err(
            field,
            format!("not rigid: rotation determinant is {det:.4}, expected +1 (a mirror image?)"),
        ));
    }
    let rows_f32: [[f32; 4]; 4] = m.map(|row| row.map(|x| x as f32));
    // glam takes columns; the file holds rows.
    Ok(Mat4::from_cols_array_2d(&rows_f32).transpose())
}

fn parse_frame(
    j: Json<'_>,
    i: usize,
    v: &Value,
    top: &IntrinsicsSpec,
    errs: &mut Errors,
) -> Option<FrameSpec> {
    let field = format!("frames[{i}]");
    let before = errs.len();
    let obj = errs.keep(j.object(&field, v))?;
    let path_field = json::join(&field, "file_path");
    let file_path = errs
        .keep(j.required(
            &field,
            obj,
            "file_path",
            "the image path, e.g. \"./start/train/rgba/0000\"",
        ))
        .and_then(|v| errs.keep(j.string(&path_field, v)))
        .and_then(|raw| {
            errs.keep(paths::normalize(raw).map_err(|m| j.err(&path_field, m.to_string())))
        });
    let m_field = json::join(&field, "transform_matrix");
    let matrix = errs
        .keep(j.required(
            &field,
            obj,
            "transform_matrix",
            "a 4x4 camera-to-world matrix",
        ))
        .and_then(|v| errs.keep(parse_matrix(j, &m_field, v)));
    let time = optional(obj, "time")
        .and_then(|v| errs.keep(j.number(&json::join(&field, "time"), v)))
        .map(|t| t as f32);
    let own = IntrinsicsSpec::parse(j, &field, obj, errs);
    let camera_to_world = matrix.filter(|_| errs.len() == before);
    Some(FrameSpec {
        field,
        file_path: file_path?,
        camera_to_world,
        time,
        intrinsics: top.overlay(&own),
    })
}

/// Reads a transforms file. `None` when nothing usable is left (errors recorded).
pub(crate) fn parse(file: &str, bytes: &[u8], errs: &mut Errors) -> Option<TransformsSpec> {
    let j = Json { file };
    let root = errs.keep(json::parse(file, bytes))?;
    let obj = errs.keep(j.object("", &root))?;
    let top = IntrinsicsSpec::parse(j, "", obj, errs);
    let list = errs.keep(j.required("", obj, "frames", "a list of frames"))?;
    let list = errs.keep(j.array("frames", list))?;
    if list.is_empty() {
        errs.push(j.err("frames", "expected at least one frame, found an empty list"));
        return None;
    }
    let frames: Vec<FrameSpec> = list
        .iter()
        .enumerate()
        .filter_map(|(i, v)| parse_frame(j, i, v, &top, errs))
        .collect();
    if frames.iter().any(|f| !f.intrinsics.has_focal()) {
        // When the field is there but bad, that error was already reported.
        if optional(obj, "camera_angle_x").is_none() && optional(obj, "fl_x").is_none() {
            errs.push(j.err(
                "camera_angle_x",
                "missing (expected camera_angle_x, or fl_x at the top level or in every frame)",
            ));
        }
        return None;
    }
    Some(TransformsSpec { frames })
}

/// Dataset-relative path of a frame's image of `kind` (`rgba`, `depth`, `semantic`) with extension `ext`.
pub(crate) fn frame_path(state: State, split: Split, kind: &str, name: &str, ext: &str) -> String {
    format!("{}/{}/{kind}/{name}{ext}", state.name(), split.name())
}

/// What the transforms file records of a frame: its name, camera and time (not its images).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FrameMeta {
    pub(crate) name: String,
    pub(crate) camera: Camera,
    pub(crate) time: f32,
}

impl FrameMeta {
    pub(crate) fn of(frame: &Frame) -> FrameMeta {
        FrameMeta {
            name: frame.name.clone(),
            camera: frame.camera,
            time: frame.time,
        }
    }
}

fn intrinsics_fields(k: &Intrinsics) -> [(&'static str, Value); 6] {
    [
        ("fl_x", f32_value(k.fx)),
        ("fl_y", f32_value(k.fy)),
        ("cx", f32_value(k.cx)),
        ("cy", f32_value(k.cy)),
        ("w", json!(k.width)),
        ("h", json!(k.height)),
    ]
}

fn frame_json(state: State, split: Split, frame: &FrameMeta, base: &Intrinsics) -> Value {
    let c = frame.camera.camera_to_world.transpose().to_cols_array_2d(); // rows of the matrix
    let mut obj = Map::new();
    obj.insert(
        "file_path".into(),
        json!(frame_path(state, split, "rgba", &frame.name, ".png")),
    );
    obj.insert(
        "transform_matrix".into(),
        Value::Array(c.iter().map(|row| f32_array(row)).collect()),
    );
    obj.insert("time".into(), f32_value(frame.time));
    // Per-frame intrinsics (nerfstudio style) only where they differ from the top level.
    for ((key, own), (_, top)) in intrinsics_fields(&frame.camera.intrinsics)
        .into_iter()
        .zip(intrinsics_fields(base))
    {
        if own != top {
            obj.insert(key.into(), own);
        }
    }
    Value::Object(obj)
}

/// Writes a view set's transforms file. The view set must be non-empty (checked by the caller).
pub(crate) fn write(state: State, split: Split, frames: &[FrameMeta]) -> Vec<u8> {
    let Some(first) = frames.first() else {
        return Vec::new();
    };
    let base = first.camera.intrinsics;
    let mut obj = Map::new();
    obj.insert("camera_angle_x".into(), f32_value(base.fov_x()));
    obj.insert("camera_angle_y".into(), f32_value(base.fov_y()));
    for (key, v) in intrinsics_fields(&base) {
        obj.insert(key.into(), v);
    }
    obj.insert(
        "frames".into(),
        Value::Array(
            frames
                .iter()
                .map(|f| frame_json(state, split, f, &base))
                .collect(),
        ),
    );
    serde_json::to_vec_pretty(&Value::Object(obj)).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> (Option<TransformsSpec>, Vec<DataError>) {
        let mut errs = Errors::default();
        let spec = parse("t.json", text.as_bytes(), &mut errs);
        (spec, errs.finish(()).err().map(|e| e.0).unwrap_or_default())
    }

    #[test]
    fn blender_style_intrinsics() {
        let (spec, errs) = parse_str(
            r#"{"camera_angle_x": 0.8, "frames": [{"file_path": "./a/rgba/0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,2],[0,0,0,1]]}]}"#,
        );
        assert!(errs.is_empty(), "{errs:?}");
        let f = &spec.unwrap().frames[0];
        assert_eq!(f.file_path, "a/rgba/0");
        assert_eq!(f.camera_to_world.unwrap().w_axis.z, 2.0);
        let k = f.intrinsics.resolve(40, 30).unwrap();
        assert!(
            (k.fx - 20.0 / 0.4f64.tan() as f32).abs() < 1e-4
                && k.fx == k.fy
                && (k.cx, k.cy) == (20.0, 15.0)
        );
    }

    #[test]
    fn all_frame_errors_are_collected() {
        let (_, errs) = parse_str(
            r#"{"camera_angle_x": 4, "frames": [{"file_path": 3, "transform_matrix": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]},
               {"file_path": "x", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "time": "0"}]}"#,
        );
        let fields: Vec<_> = errs
            .iter()
            .map(|e| e.field.clone().unwrap_or_default())
            .collect();
        assert_eq!(
            fields,
            [
                "camera_angle_x",
                "frames[0].file_path",
                "frames[0].transform_matrix",
                "frames[1].time"
            ]
        );
        assert!(
            errs[2]
                .message
                .contains("not rigid: columns not orthonormal")
        );
    }
}
