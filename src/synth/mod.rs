//! Procedural articulated objects in the 16 categories of the paper's Articulate-100 benchmark.
//!
//! PartNet-Mobility cannot ship with artmesh, so the benchmark suite is generated: [`generate`] turns a
//! [`SynthParams`] (category, movable-part count, seed) into the same [`ArticulatedObject`] a URDF import gives,
//! with seeded variation of size, proportions, part count and joint placement, and procedural textures (wood
//! grain, paint, brushed metal, near-textureless plastic; see [`texture`]). The same parameters always give
//! the same object, bit for bit, on every target.
//!
//! Conventions shared by all categories: metres, z up, the object stands on z = 0 (or lies on it) centred
//! near the origin, its front faces −y (where cameras see doors and drawers open). Part 0 is the static body;
//! every movable part hangs directly on it (no joint chains), so each part's motion is one joint.

mod bucket;
pub mod builder;
mod categories;
mod suite;
pub mod texture;

pub use bucket::PartBucket;
pub use suite::{FULL_BUCKETS, SuiteEntry, SuiteKind, suite_plan};

use std::ops::RangeInclusive;

use crate::object::ArticulatedObject;
use crate::rng::Rng;

/// An object category of the paper's benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Category {
    /// A box with hinged lid or flaps.
    Box,
    /// Glasses with folding temples.
    Eyeglasses,
    /// A tap with turning spout and handles.
    Faucet,
    /// A chair whose seat and back fold.
    FoldingChair,
    /// A folding knife.
    Knife,
    /// A laptop with a hinged screen.
    Laptop,
    /// An oven with a drop-down door and turning knobs.
    Oven,
    /// A pen with a sliding cap or push button.
    Pen,
    /// Pliers.
    Pliers,
    /// A fridge with doors and drawers.
    Refrigerator,
    /// Cabinets and chests of drawers and doors.
    StorageFurniture,
    /// A suitcase with lid and telescopic handle.
    Suitcase,
    /// A desk or table with drawers.
    Table,
    /// A toilet with seat and lid.
    Toilet,
    /// A bin with lid and pedal.
    TrashCan,
    /// A window with sliding or hinged sashes.
    Window,
}

impl Category {
    /// All categories in the paper's (alphabetical) order.
    pub const ALL: [Category; 16] = [
        Category::Box,
        Category::Eyeglasses,
        Category::Faucet,
        Category::FoldingChair,
        Category::Knife,
        Category::Laptop,
        Category::Oven,
        Category::Pen,
        Category::Pliers,
        Category::Refrigerator,
        Category::StorageFurniture,
        Category::Suitcase,
        Category::Table,
        Category::Toilet,
        Category::TrashCan,
        Category::Window,
    ];

    /// The paper's name, e.g. `"StorageFurniture"`.
    pub fn name(self) -> &'static str {
        match self {
            Category::Box => "Box",
            Category::Eyeglasses => "Eyeglasses",
            Category::Faucet => "Faucet",
            Category::FoldingChair => "FoldingChair",
            Category::Knife => "Knife",
            Category::Laptop => "Laptop",
            Category::Oven => "Oven",
            Category::Pen => "Pen",
            Category::Pliers => "Pliers",
            Category::Refrigerator => "Refrigerator",
            Category::StorageFurniture => "StorageFurniture",
            Category::Suitcase => "Suitcase",
            Category::Table => "Table",
            Category::Toilet => "Toilet",
            Category::TrashCan => "TrashCan",
            Category::Window => "Window",
        }
    }

    /// Lower-case name for file names, e.g. `"storagefurniture"`.
    pub fn slug(self) -> String {
        self.name().to_ascii_lowercase()
    }

    /// Parses a category: the paper's name in any case, with or without `_`/`-`/spaces
    /// (`storage_furniture`), or a short alias (`storage`, `fridge`, `chair`, `bin`, `glasses`).
    pub fn parse(text: &str) -> Result<Category, UnknownCategory> {
        let key: String = text
            .chars()
            .filter(|c| !matches!(c, '_' | '-' | ' '))
            .collect::<String>()
            .to_ascii_lowercase();
        let alias = match key.as_str() {
            "storage" | "cabinet" => Some(Category::StorageFurniture),
            "fridge" => Some(Category::Refrigerator),
            "chair" => Some(Category::FoldingChair),
            "bin" | "trash" => Some(Category::TrashCan),
            "glasses" => Some(Category::Eyeglasses),
            "tap" => Some(Category::Faucet),
            _ => None,
        };
        alias
            .or_else(|| Category::ALL.into_iter().find(|c| c.slug() == key))
            .ok_or_else(|| UnknownCategory(text.to_string()))
    }

    /// Movable-part counts this category can be generated with.
    pub fn movable_parts(self) -> RangeInclusive<usize> {
        match self {
            Category::Box => 1..=2,
            Category::Eyeglasses => 1..=2,
            Category::Faucet => 1..=3,
            Category::FoldingChair => 1..=2,
            Category::Knife => 1..=1,
            Category::Laptop => 1..=1,
            Category::Oven => 1..=6,
            Category::Pen => 1..=1,
            Category::Pliers => 1..=1,
            Category::Refrigerator => 1..=4,
            Category::StorageFurniture => 1..=10,
            Category::Suitcase => 1..=3,
            Category::Table => 1..=9,
            Category::Toilet => 1..=3,
            Category::TrashCan => 1..=3,
            Category::Window => 1..=4,
        }
    }
}

impl std::fmt::Display for Category {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A category name [`Category::parse`] does not know; the message lists the valid ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown category '{0}': expected one of {names}", names = category_names())]
pub struct UnknownCategory(pub String);

/// The paper's category names, comma-separated.
fn category_names() -> String {
    let names: Vec<&str> = Category::ALL.iter().map(|c| c.name()).collect();
    names.join(", ")
}

/// Why [`generate`] made no object.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GenerateError {
    /// The category cannot have the asked number of movable parts.
    #[error("{category} objects have {}..={} movable parts, not {asked}", .range.start(), .range.end())]
    PartCount {
        /// The category.
        category: Category,
        /// The counts it supports ([`Category::movable_parts`]).
        range: RangeInclusive<usize>,
        /// The count asked for.
        asked: usize,
    },
    /// A generator broke its own contract (a bug, not an input problem).
    #[error("internal error: {category} generator made {got} movable parts instead of {parts}")]
    WrongPartCount {
        /// The category.
        category: Category,
        /// Movable parts made.
        got: usize,
        /// Movable parts asked for.
        parts: usize,
    },
}

/// What to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SynthParams {
    /// Category.
    pub category: Category,
    /// Movable parts; `None` draws a count from [`Category::movable_parts`] with the seed.
    pub movable_parts: Option<usize>,
    /// Seed of every random choice.
    pub seed: u64,
}

/// Generates the object described by `params`. Errors when the category cannot have that many movable parts.
/// The object's name is `<category>_<parts>p_s<seed>`.
pub fn generate(params: &SynthParams) -> Result<ArticulatedObject, GenerateError> {
    let range = params.category.movable_parts();
    let parts = match params.movable_parts {
        Some(n) if range.contains(&n) => n,
        Some(n) => {
            return Err(GenerateError::PartCount {
                category: params.category,
                range,
                asked: n,
            });
        }
        None => Rng::new(params.seed).int_in(*range.start(), *range.end()),
    };
    // Mix category and part count into the seed, so one seed gives unrelated shapes across categories and
    // part counts rather than the same layout with a different number of doors.
    let mixed = params.seed
        ^ (params.category as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (parts as u64 + 1).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    let mut rng = Rng::new(mixed);
    let mut object = categories::build(params.category, parts, &mut rng);
    object.name = format!("{}_{parts}p_s{}", params.category.slug(), params.seed);
    let got = object.parts().movable_count();
    if got != parts {
        return Err(GenerateError::WrongPartCount {
            category: params.category,
            got,
            parts,
        });
    }
    Ok(object)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn category_names_parse_back() {
        for c in Category::ALL {
            assert_eq!(Category::parse(c.name()), Ok(c));
            assert_eq!(Category::parse(&c.slug()), Ok(c));
        }
        assert_eq!(Category::parse("storage"), Ok(Category::StorageFurniture));
        assert_eq!(
            Category::parse("Storage_Furniture"),
            Ok(Category::StorageFurniture)
        );
        let err = Category::parse("sofa").unwrap_err().to_string();
        assert!(err.contains("sofa") && err.contains("TrashCan"), "{err}");
    }
}
