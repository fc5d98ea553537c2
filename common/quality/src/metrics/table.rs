//! The metric table: every grasp metric graspopt computes, in one list.
//!
//! Each entry of [`metric_table!`] below names a metric (the [`Metric`] variant) and says
//! how it is called, stored and printed, and how it is computed from a wrench set. The rest
//! of graspopt reads this list: the values a trial carries ([`super::Metrics`] and the
//! protocol's `MetricValues`), the journal's columns, the headers of `export` and `scan`,
//! the printing of `graspopt quality` and `graspopt trial`, and which metrics `--metric`
//! accepts as the score.
//!
//! **To add a metric**: add one entry at the end of the list (the order is the order of
//! every output, and old journals gain the new column at the end) and its compute function
//! (here, or in a file of its own for a longer computation). Nothing else changes: a
//! journal without the column gains it when opened, and reads it as missing for older
//! trials.

use crate::error::QualityError;
use crate::wrench::Wrench;

use super::{MetricsOptions, grasp_wrench_volume};

/// What kind of value a metric has: how it is stored (a journal column's type) and printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A whole number (an SQL `INTEGER`).
    Count,
    /// Yes or no (an SQL `INTEGER`, 0 or 1).
    Flag,
    /// A real number, always finite (an SQL `REAL`).
    Real,
}

/// One metric's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    Count(u32),
    Flag(bool),
    Real(f64),
}

impl Value {
    /// The value as a number: a count as itself, a flag as 0 or 1.
    pub fn as_f64(self) -> f64 {
        match self {
            Value::Count(n) => f64::from(n),
            Value::Flag(b) => f64::from(u8::from(b)),
            Value::Real(x) => x,
        }
    }
}

/// As `Display` writes the number or flag (`6`, `true`, `0.25`, `0`).
impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Count(n) => n.fmt(f),
            Value::Flag(b) => b.fmt(f),
            Value::Real(x) => x.fmt(f),
        }
    }
}

/// What a metric's compute function gets: the wrench set, the options, and what several
/// metrics share (computed once, before the table is evaluated).
#[derive(Debug, Clone, Copy)]
pub struct WrenchSet<'a> {
    /// The wrenches: checked (finite, bounded, not empty).
    pub wrenches: &'a [Wrench],
    pub options: &'a MetricsOptions,
    /// The affine rank of the wrenches, 0 to 6.
    pub rank: usize,
    /// The distance from the origin to the wrench hull (finite, 0 when inside).
    pub distance: f64,
    /// The origin is strictly inside the hull.
    pub force_closure: bool,
    /// The Largest Sphere radius with force closure, else 0 (finite).
    pub epsilon: f64,
}

/// A compute function: the metric's value for a wrench set, `None` when it is not computed
/// (an expensive metric not asked for).
pub type Compute = fn(&WrenchSet<'_>) -> Result<Option<Value>, QualityError>;

/// One entry of the metric table.
#[derive(Debug, Clone, Copy)]
pub struct MetricDef {
    /// The name in files and on the command line: the journal's column, the CSV and JSON
    /// header, the protocol's key and a `--metric` name (`bw`).
    pub key: &'static str,
    /// Other names `--metric` accepts (`ls` for `epsilon`).
    pub aliases: &'static [&'static str],
    /// The words of text output (`graspopt trial`): `force closure`.
    pub label: &'static str,
    /// The header of `graspopt quality --format table` (`fc`) and its column width.
    pub short: &'static str,
    pub width: usize,
    pub kind: Kind,
    /// It may be the score an optimiser maximises (`--metric`).
    pub objective: bool,
    /// Computed only when asked (see [`MetricsOptions`]): text output prints it last, and
    /// the CSV export leaves its column out when no trial has it.
    pub optional: bool,
    /// Text output writes it in scientific notation (its values are tiny: the volume).
    pub scientific: bool,
    /// A scan's CSV has its column.
    pub in_scan: bool,
    /// What it measures, for people.
    pub description: &'static str,
    /// How it is computed from the wrench set.
    pub compute: Compute,
}

impl MetricDef {
    /// A metric of `kind` named `key`, with the defaults: no alias, labelled by its key,
    /// not an objective, always computed, plain notation, not in scans.
    pub const fn new(key: &'static str, kind: Kind, compute: Compute) -> Self {
        MetricDef {
            key,
            aliases: &[],
            label: key,
            short: key,
            width: 15,
            kind,
            objective: false,
            optional: false,
            scientific: false,
            in_scan: false,
            description: "",
            compute,
        }
    }
    pub const fn aliases(self, aliases: &'static [&'static str]) -> Self {
        MetricDef { aliases, ..self }
    }
    pub const fn label(self, label: &'static str) -> Self {
        MetricDef { label, ..self }
    }
    pub const fn short(self, short: &'static str, width: usize) -> Self {
        MetricDef {
            short,
            width,
            ..self
        }
    }
    pub const fn objective(self) -> Self {
        MetricDef {
            objective: true,
            ..self
        }
    }
    pub const fn optional(self) -> Self {
        MetricDef {
            optional: true,
            ..self
        }
    }
    pub const fn scientific(self) -> Self {
        MetricDef {
            scientific: true,
            ..self
        }
    }
    pub const fn in_scan(self) -> Self {
        MetricDef {
            in_scan: true,
            ..self
        }
    }
    pub const fn describe(self, description: &'static str) -> Self {
        MetricDef {
            description,
            ..self
        }
    }
}

/// Declares [`Metric`] (one variant per entry), [`Metric::ALL`] and [`TABLE`] (the entries,
/// in the same order) from one list.
macro_rules! metric_table {
    ($($variant:ident => $def:expr,)+) => {
        /// A grasp metric: an entry of [`TABLE`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Metric {
            $($variant,)+
        }

        /// How many metrics there are.
        pub const COUNT: usize = [$(Metric::$variant,)+].len();

        impl Metric {
            /// Every metric, in table order.
            pub const ALL: [Metric; COUNT] = [$(Metric::$variant,)+];
        }

        /// The metric table, in [`Metric`] order.
        pub const TABLE: [MetricDef; COUNT] = [$($def,)+];
    };
}

metric_table! {
    Rank => MetricDef::new("rank", Kind::Count, |s| Ok(Some(Value::Count(s.rank as u32))))
        .short("rank", 4)
        .describe("affine rank of the wrenches (0 to 6); below 6 there is no force closure"),
    ForceClosure => MetricDef::new("force_closure", Kind::Flag, |s| {
        Ok(Some(Value::Flag(s.force_closure)))
    })
    .label("force closure")
    .short("fc", 5)
    .in_scan()
    .describe("the origin strictly inside the wrench hull"),
    Epsilon => MetricDef::new("epsilon", Kind::Real, |s| Ok(Some(Value::Real(s.epsilon))))
        .aliases(&["ls"])
        .objective()
        .in_scan()
        .describe("Largest Sphere (Ferrari-Canny) radius, 0 without force closure"),
    Volume => MetricDef::new("volume", Kind::Real, volume)
        .aliases(&["gwv"])
        .objective()
        .optional()
        .scientific()
        .describe("Grasp Wrench Volume: the 6-volume of the wrench hull"),
    Distance => MetricDef::new("distance", Kind::Real, |s| Ok(Some(Value::Real(s.distance))))
        .in_scan()
        .describe("distance from the origin to the wrench hull, 0 when inside"),
    Bw => MetricDef::new("bw", Kind::Real, bimodal)
        .short("bw", 16)
        .objective()
        .describe("Bimodal Wrench: epsilon with force closure, else -distance"),
    Isotropy => MetricDef::new("isotropy", Kind::Real, isotropy)
        .objective()
        .in_scan()
        .describe("grasp isotropy index: smallest over largest singular value of the wrenches"),
}

/// The grasp isotropy index (Roa and Suárez 2015, "Grasp quality measures: review and
/// performance", Autonomous Robots 38): `sigma_min / sigma_max` of the 6 x m matrix `G` whose
/// columns are the wrenches, from the eigenvalues of `G G^T` (the sum of `w w^T`). 1 when
/// every direction of wrench space is reached alike, 0 when `G` has rank below 6 (a ratio
/// below 1e-7, the rounding of the eigenvalues, counts as 0).
fn isotropy(s: &WrenchSet<'_>) -> Result<Option<Value>, QualityError> {
    let mut gram = nalgebra::Matrix6::<f64>::zeros();
    for w in s.wrenches {
        gram.ger(1.0, w, w, 1.0);
    }
    let eigen = gram.symmetric_eigenvalues();
    let (low, high) = (eigen.min().max(0.0), eigen.max());
    let ratio = if high > 0.0 { (low / high).sqrt() } else { 0.0 };
    Ok(Some(Value::Real(if ratio < 1e-7 { 0.0 } else { ratio })))
}

fn volume(s: &WrenchSet<'_>) -> Result<Option<Value>, QualityError> {
    if !s.options.volume {
        return Ok(None);
    }
    Ok(Some(Value::Real(grasp_wrench_volume(s.wrenches)?)))
}

fn bimodal(s: &WrenchSet<'_>) -> Result<Option<Value>, QualityError> {
    Ok(Some(Value::Real(if s.force_closure {
        s.epsilon
    } else {
        -s.distance
    })))
}

impl Metric {
    /// Its table entry.
    pub fn def(self) -> &'static MetricDef {
        &TABLE[self as usize]
    }

    /// Its key: `bw`, `epsilon`, `volume`...
    pub fn key(self) -> &'static str {
        self.def().key
    }

    /// The name users see (the key).
    pub fn name(self) -> &'static str {
        self.key()
    }

    /// The metric of this key, any metric.
    pub fn from_key(key: &str) -> Option<Metric> {
        Metric::ALL.into_iter().find(|m| m.key() == key)
    }

    /// The metrics that may be the score (`--metric`): the default first, then the others
    /// in table order.
    pub fn objectives() -> impl Iterator<Item = Metric> {
        let others = Metric::ALL
            .into_iter()
            .filter(|&m| m.def().objective && m != Metric::default());
        std::iter::once(Metric::default()).chain(others)
    }

    /// An objective by its key or an alias (`bw`, `epsilon` or `ls`, `volume` or `gwv`).
    pub fn parse(name: &str) -> Result<Self, QualityError> {
        Metric::objectives()
            .find(|m| m.key() == name || m.def().aliases.contains(&name))
            .ok_or_else(|| QualityError::UnknownMetric {
                name: name.to_string(),
            })
    }
}

/// The score when none is chosen: the Bimodal Wrench metric (thesis 2.6).
impl Default for Metric {
    fn default() -> Self {
        Metric::Bw
    }
}

impl std::fmt::Display for Metric {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The objectives as `--metric` accepts them, for messages: `bw, epsilon (ls) or volume (gwv)`.
pub fn objective_names() -> String {
    let names: Vec<String> = Metric::objectives()
        .map(|m| match m.def().aliases {
            [] => m.key().to_string(),
            aliases => format!("{} ({})", m.key(), aliases.join(", ")),
        })
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// A score metric is written as its key; read back only as an objective's key (as serde
/// names enum variants).
impl serde::Serialize for Metric {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.key())
    }
}

impl<'de> serde::Deserialize<'de> for Metric {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let key = <std::borrow::Cow<'de, str>>::deserialize(d)?;
        Metric::objectives()
            .find(|m| m.key() == key)
            .ok_or_else(|| {
                let expected: Vec<String> = Metric::objectives()
                    .map(|m| format!("`{}`", m.key()))
                    .collect();
                serde::de::Error::custom(format_args!(
                    "unknown variant `{key}`, expected one of {}",
                    expected.join(", ")
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_in_metric_order_with_unique_keys() {
        for (i, m) in Metric::ALL.into_iter().enumerate() {
            assert_eq!(m as usize, i);
            assert_eq!(Metric::from_key(m.key()), Some(m));
        }
        let mut keys: Vec<&str> = TABLE.iter().map(|d| d.key).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), COUNT);
    }

    #[test]
    fn objectives_parse_by_key_or_alias() {
        assert_eq!(Metric::parse("ls").unwrap(), Metric::Epsilon);
        assert_eq!(Metric::parse("gwv").unwrap(), Metric::Volume);
        assert!(Metric::parse("rank").is_err());
        assert!(objective_names().starts_with("bw, epsilon (ls)"));
        let e: serde_json::Error = serde_json::from_str::<Metric>("\"rank\"").unwrap_err();
        let e = e.to_string();
        assert!(
            e.starts_with("unknown variant `rank`, expected one of `bw`, `epsilon`, `volume`"),
            "{e}"
        );
    }
}
