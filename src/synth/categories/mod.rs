//! One generator per category. Each `build(parts, rng)` returns an object with exactly `parts` movable parts
//! (within [`Category::movable_parts`]), built with [`super::builder::ObjectBuilder`].

mod laptop;
mod refrigerator;
mod shapes_b;
mod storage_furniture;
mod suitcase;
mod table;
mod toilet;
mod trash_can;
mod window;

use super::Category;
use crate::object::ArticulatedObject;
use crate::rng::Rng;

/// Dispatches to the category's generator.
pub(super) fn build(category: Category, parts: usize, rng: &mut Rng) -> ArticulatedObject {
    match category {
        Category::Laptop => laptop::build(parts, rng),
        Category::Refrigerator => refrigerator::build(parts, rng),
        Category::StorageFurniture => storage_furniture::build(parts, rng),
        Category::Suitcase => suitcase::build(parts, rng),
        Category::Table => table::build(parts, rng),
        Category::Toilet => toilet::build(parts, rng),
        Category::TrashCan => trash_can::build(parts, rng),
        Category::Window => window::build(parts, rng),
        _ => laptop::build(parts, rng),
    }
}
