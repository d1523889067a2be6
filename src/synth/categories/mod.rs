//! One generator per category. Each `build(parts, rng)` returns an object with exactly `parts` movable parts
//! (within [`Category::movable_parts`]), built with [`super::builder::ObjectBuilder`]. Shapes beyond the
//! builder's live in `shapes_a` (extruded outlines, bent tubes) and `shapes_b` (carcasses, drawers, doors,
//! handles).

mod box_;
mod eyeglasses;
mod faucet;
mod folding_chair;
mod knife;
mod laptop;
mod oven;
mod pen;
mod pliers;
mod refrigerator;
mod shapes_a;
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
        Category::Box => box_::build(parts, rng),
        Category::Eyeglasses => eyeglasses::build(parts, rng),
        Category::Faucet => faucet::build(parts, rng),
        Category::FoldingChair => folding_chair::build(parts, rng),
        Category::Knife => knife::build(parts, rng),
        Category::Laptop => laptop::build(parts, rng),
        Category::Oven => oven::build(parts, rng),
        Category::Pen => pen::build(parts, rng),
        Category::Pliers => pliers::build(parts, rng),
        Category::Refrigerator => refrigerator::build(parts, rng),
        Category::StorageFurniture => storage_furniture::build(parts, rng),
        Category::Suitcase => suitcase::build(parts, rng),
        Category::Table => table::build(parts, rng),
        Category::Toilet => toilet::build(parts, rng),
        Category::TrashCan => trash_can::build(parts, rng),
        Category::Window => window::build(parts, rng),
    }
}
