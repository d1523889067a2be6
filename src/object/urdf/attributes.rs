//! Attribute values of URDF elements: required attributes, finite numbers and number vectors, `<origin>`
//! transforms, and errors that name the element path and line.

use glam::{Affine3A, EulerRot, Quat, Vec3};
use roxmltree::Node;

use crate::data::DataError;

use super::reader::{Reader, child};

impl Reader<'_, '_> {
    /// An error at `node` (or its attribute `attr`): field = `path@attr (line N)`.
    pub(super) fn err(
        &self,
        node: Node,
        path: &str,
        attr: Option<&str>,
        message: impl Into<String>,
    ) -> DataError {
        let pos = attr
            .and_then(|a| node.attribute_node(a))
            .map_or(node.range().start, |a| a.range_value().start);
        let line = self.doc.text_pos_at(pos).row;
        let field = match attr {
            Some(a) => format!("{path}@{a} (line {line})"),
            None => format!("{path} (line {line})"),
        };
        DataError::field(self.file, field, message)
    }

    /// The attribute `attr` of `node`; an error if it is missing.
    pub(super) fn required<'n>(
        &self,
        node: Node<'n, '_>,
        path: &str,
        attr: &str,
    ) -> Result<&'n str, DataError> {
        node.attribute(attr)
            .ok_or_else(|| self.err(node, path, None, format!("missing attribute '{attr}'")))
    }

    /// The optional attribute `attr` as a finite number.
    pub(super) fn number(
        &self,
        node: Node,
        path: &str,
        attr: &str,
    ) -> Result<Option<f32>, DataError> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        match parse_finite(text) {
            Some(v) => Ok(Some(v)),
            None => Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected a finite number, found {text:?}"),
            )),
        }
    }

    /// `n` whitespace-separated finite numbers (commas also accepted when `commas`).
    pub(super) fn numbers<const N: usize>(
        &self,
        node: Node,
        path: &str,
        attr: &str,
        commas: bool,
    ) -> Result<Option<[f32; N]>, DataError> {
        let Some(text) = node.attribute(attr) else {
            return Ok(None);
        };
        let tokens: Vec<&str> = if commas {
            text.split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
                .collect()
        } else {
            text.split_whitespace().collect()
        };
        let values: Vec<f32> = tokens.iter().filter_map(|t| parse_finite(t)).collect();
        let words = ["zero", "one", "two", "three", "four"];
        let count = words.get(N).copied().unwrap_or("several");
        let sep = if commas {
            "separated by spaces or commas"
        } else {
            "separated by spaces"
        };
        match <[f32; N]>::try_from(values) {
            Ok(v) if tokens.len() == N => Ok(Some(v)),
            _ => Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected {count} finite numbers {sep}, found {text:?}"),
            )),
        }
    }

    /// `<origin xyz rpy>` child of `node`, or the identity.
    pub(super) fn origin(&self, node: Node, path: &str) -> Result<Affine3A, DataError> {
        let Some(o) = child(node, "origin") else {
            return Ok(Affine3A::IDENTITY);
        };
        let path = format!("{path}/origin");
        let xyz = self
            .numbers::<3>(o, &path, "xyz", false)?
            .unwrap_or([0.0; 3]);
        let [roll, pitch, yaw] = self
            .numbers::<3>(o, &path, "rpy", false)?
            .unwrap_or([0.0; 3]);
        // URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z = Rz * Ry * Rx.
        let rotation = Quat::from_euler(EulerRot::ZYX, yaw, pitch, roll);
        Ok(Affine3A::from_rotation_translation(
            rotation,
            Vec3::from_array(xyz),
        ))
    }

    /// A required non-negative number.
    pub(super) fn positive(&self, node: Node, path: &str, attr: &str) -> Result<f32, DataError> {
        let v = self
            .number(node, path, attr)?
            .ok_or_else(|| self.err(node, path, None, format!("missing attribute '{attr}'")))?;
        if v < 0.0 {
            return Err(self.err(
                node,
                path,
                Some(attr),
                format!("expected a non-negative number, found {v}"),
            ));
        }
        Ok(v)
    }
}

/// A finite number, or `None`.
pub(super) fn parse_finite(text: &str) -> Option<f32> {
    text.trim().parse::<f32>().ok().filter(|v| v.is_finite())
}
