//! Benchmark tables: per-object metrics averaged into the columns of the paper's Table 1 (part-count buckets
//! 2 / 3 / 4-5 / 6+ and All) and of its appendix table (one column per category and All).
//!
//! A column's value is the mean over its objects of their per-object values, skipping objects where the metric
//! does not exist (Axis Pos of an object without revolute joints, CD without meshes). This reproduces the
//! paper's numbers: its "All" column is the object-weighted mean of the bucket columns. The Markdown keeps the
//! paper's layout — metrics as rows, columns headed `label (objects)` — with the five paper rows first and the
//! extra rows (split Part Motion, Chamfer in mm, type accuracy, joint-count mismatches) below.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::report::ObjectMetrics;
use crate::synth::PartBucket;

/// One table column: the object-averaged metrics of a group of objects.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ColumnSummary {
    /// Column label (`2 Parts`, a category, `All`).
    pub label: String,
    /// Objects in the column.
    pub objects: usize,
    /// Axis Ang (°).
    pub axis_ang: Option<f64>,
    /// Axis Pos (0.1 m).
    pub axis_pos: Option<f64>,
    /// Part Motion (° / m mixed, as the paper).
    pub part_motion: Option<f64>,
    /// Part Motion of revolute joints (°).
    pub part_motion_revolute: Option<f64>,
    /// Part Motion of prismatic joints (m).
    pub part_motion_prismatic: Option<f64>,
    /// CD-s, peer convention (mean squared distances × 1000).
    pub cd_s: Option<f64>,
    /// CD-m, peer convention.
    pub cd_m: Option<f64>,
    /// CD-s, mean distance in mm.
    pub cd_s_mm: Option<f64>,
    /// CD-m, mean distance in mm.
    pub cd_m_mm: Option<f64>,
    /// Type accuracy (fraction of GT joints matched with the right type), averaged over objects.
    pub type_accuracy: Option<f64>,
    /// Total wrong-type pairs.
    pub type_errors: usize,
    /// Total GT joints without a prediction.
    pub missed_joints: usize,
    /// Total predicted joints without a GT joint.
    pub extra_joints: usize,
}

fn mean(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let (sum, n) = values
        .flatten()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

impl ColumnSummary {
    /// Averages `objects` into a column named `label`.
    pub fn new(label: &str, objects: &[&ObjectMetrics]) -> Self {
        let col = |f: fn(&ObjectMetrics) -> Option<f64>| mean(objects.iter().map(|o| f(o)));
        ColumnSummary {
            label: label.into(),
            objects: objects.len(),
            axis_ang: col(|o| o.axis_ang),
            axis_pos: col(|o| o.axis_pos),
            part_motion: col(|o| o.part_motion),
            part_motion_revolute: col(|o| o.part_motion_revolute),
            part_motion_prismatic: col(|o| o.part_motion_prismatic),
            cd_s: col(|o| o.cd_s.map(|c| c.cd_peer)),
            cd_m: col(|o| o.cd_m.map(|c| c.cd_peer)),
            cd_s_mm: col(|o| o.cd_s.map(|c| c.cd_mm)),
            cd_m_mm: col(|o| o.cd_m.map(|c| c.cd_mm)),
            type_accuracy: col(|o| o.type_accuracy),
            type_errors: objects.iter().map(|o| o.type_errors).sum(),
            missed_joints: objects.iter().map(|o| o.unmatched_gt.len()).sum(),
            extra_joints: objects.iter().map(|o| o.unmatched_pred.len()).sum(),
        }
    }
}

/// A benchmark table: columns of object-averaged metrics, the last one `All`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BenchmarkTable {
    /// The columns in display order.
    pub columns: Vec<ColumnSummary>,
}

/// Rows of the Markdown table: label and value of a column (already formatted).
type Row = (&'static str, fn(&ColumnSummary) -> String);

fn fmt(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.2}"))
}

const ROWS: [Row; 11] = [
    ("Axis Ang ↓ (°)", |c| fmt(c.axis_ang)),
    ("Axis Pos ↓ (0.1 m)", |c| fmt(c.axis_pos)),
    ("Part Motion ↓ (° / m)", |c| fmt(c.part_motion)),
    ("CD-s ↓", |c| fmt(c.cd_s)),
    ("CD-m ↓", |c| fmt(c.cd_m)),
    ("Part Motion rev. ↓ (°)", |c| fmt(c.part_motion_revolute)),
    ("Part Motion pris. ↓ (m)", |c| fmt(c.part_motion_prismatic)),
    ("CD-s ↓ (mm)", |c| fmt(c.cd_s_mm)),
    ("CD-m ↓ (mm)", |c| fmt(c.cd_m_mm)),
    ("Type Acc ↑ (%)", |c| {
        fmt(c.type_accuracy.map(|a| a * 100.0))
    }),
    ("Missed / extra joints", |c| {
        format!("{} / {}", c.missed_joints, c.extra_joints)
    }),
];

impl BenchmarkTable {
    /// The paper's Table 1 layout: 2 / 3 / 4-5 / 6+ parts, then All (every object, also those with < 2 parts).
    /// Empty buckets stay as columns with no values.
    pub fn by_part_count(objects: &[ObjectMetrics]) -> Self {
        let mut columns: Vec<ColumnSummary> = PartBucket::ALL
            .iter()
            .map(|&b| {
                let group: Vec<&ObjectMetrics> = objects
                    .iter()
                    .filter(|o| PartBucket::of(o.part_count) == Some(b))
                    .collect();
                ColumnSummary::new(b.label(), &group)
            })
            .collect();
        columns.push(ColumnSummary::new(
            "All",
            &objects.iter().collect::<Vec<_>>(),
        ));
        BenchmarkTable { columns }
    }

    /// The appendix table layout: one column per category (sorted by name), then All.
    pub fn by_category(objects: &[ObjectMetrics]) -> Self {
        let mut groups: BTreeMap<&str, Vec<&ObjectMetrics>> = BTreeMap::new();
        for o in objects {
            groups.entry(o.category.as_str()).or_default().push(o);
        }
        let mut columns: Vec<ColumnSummary> = groups
            .iter()
            .map(|(label, group)| ColumnSummary::new(label, group))
            .collect();
        columns.push(ColumnSummary::new(
            "All",
            &objects.iter().collect::<Vec<_>>(),
        ));
        BenchmarkTable { columns }
    }

    /// The column labelled `label`, if any.
    pub fn column(&self, label: &str) -> Option<&ColumnSummary> {
        self.columns.iter().find(|c| c.label == label)
    }

    /// GitHub Markdown: a `Metric` column, then one column per group headed `label (objects)`; values with two
    /// decimals as in the paper, `-` where a group has no value.
    pub fn to_markdown(&self) -> String {
        let mut out = String::from("| Metric |");
        for c in &self.columns {
            let _ = write!(out, " {} ({}) |", c.label, c.objects);
        }
        out.push_str("\n| --- |");
        for _ in &self.columns {
            out.push_str(" ---: |");
        }
        out.push('\n');
        for (name, value) in ROWS {
            let _ = write!(out, "| {name} |");
            for c in &self.columns {
                let _ = write!(out, " {} |", value(c));
            }
            out.push('\n');
        }
        out
    }
}
