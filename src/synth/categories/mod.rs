//! One generator per category. Each `build(parts, rng)` returns an object with exactly `parts` movable parts
//! (within [`Category::movable_parts`]), built with [`super::builder::ObjectBuilder`].

mod laptop;

use super::Category;
use crate::object::ArticulatedObject;
use crate::rng::Rng;

/// Dispatches to the category's generator.
pub(super) fn build(category: Category, parts: usize, rng: &mut Rng) -> ArticulatedObject {
    match category {
        Category::Laptop => laptop::build(parts, rng),
        _ => laptop::build(parts, rng),
    }
}
