//! Checks that what is about to be written holds only finite numbers. JSON has no NaN or
//! infinity (they would be written as `null`), and a PLY or URDF holding them is refused or
//! misread by the tools that load it, so an input that leads to one is refused instead.

use glam::{Mat4, Vec3};

use super::error::DataError;

/// The first value of `values` that is not finite, with its position.
pub fn first_non_finite(values: impl IntoIterator<Item = f32>) -> Option<(usize, f32)> {
    values.into_iter().enumerate().find(|(_, v)| !v.is_finite())
}

/// `Ok` when every value is finite; otherwise an error naming `file`, `field` and the value.
pub fn ensure_finite(
    file: &str,
    field: &str,
    values: impl IntoIterator<Item = f32>,
) -> Result<(), DataError> {
    match first_non_finite(values) {
        None => Ok(()),
        Some((i, v)) => Err(DataError::field(
            file,
            field,
            format!(
                "cannot write: value {i} is {v}, not a finite number (an input out of range led to it)"
            ),
        )),
    }
}

/// The numbers of a list of points, in order.
pub fn point_values(points: &[Vec3]) -> impl Iterator<Item = f32> + '_ {
    points.iter().flat_map(|p| p.to_array())
}

/// The sixteen numbers of a matrix.
pub fn matrix_values(m: &Mat4) -> [f32; 16] {
    m.to_cols_array()
}
