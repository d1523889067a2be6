//! The part-count buckets of the paper's Table 1 (2 / 3 / 4-5 / 6+ parts): the suite spreads its objects
//! over them, and the benchmark tables average metrics by them.

/// Part-count bucket of the paper's Table 1 (part count = 1 + movable parts).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum PartBucket {
    /// 2 parts.
    Two,
    /// 3 parts.
    Three,
    /// 4 or 5 parts.
    FourToFive,
    /// 6 parts or more.
    SixPlus,
}

impl PartBucket {
    /// The buckets in table order.
    pub const ALL: [PartBucket; 4] = [
        PartBucket::Two,
        PartBucket::Three,
        PartBucket::FourToFive,
        PartBucket::SixPlus,
    ];

    /// The bucket of an object with `part_count` parts; `None` below 2 (nothing moves).
    pub fn of(part_count: usize) -> Option<PartBucket> {
        match part_count {
            0 | 1 => None,
            2 => Some(PartBucket::Two),
            3 => Some(PartBucket::Three),
            4 | 5 => Some(PartBucket::FourToFive),
            _ => Some(PartBucket::SixPlus),
        }
    }

    /// Column label as in the paper.
    pub fn label(self) -> &'static str {
        match self {
            PartBucket::Two => "2 Parts",
            PartBucket::Three => "3 Parts",
            PartBucket::FourToFive => "4-5 Parts",
            PartBucket::SixPlus => "6+ Parts",
        }
    }
}
