//! [`Metrics`]: the value of every metric of the table for one wrench set.

use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::table::{COUNT, Kind, Metric, MetricDef, TABLE, Value};

/// The metrics of one wrench set: a value per entry of the [`TABLE`], `None` for one not
/// computed (the volume, unless asked for).
///
/// Written (serde) as an object of the keys in table order, a metric not computed as
/// `null`; read back by key, a missing key as not computed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Metrics {
    values: [Option<Value>; COUNT],
}

impl Metrics {
    /// Metrics from a value per table entry.
    pub fn from_values(values: [Option<Value>; COUNT]) -> Self {
        Metrics { values }
    }

    /// The value of `metric`, `None` if it was not computed.
    pub fn get(&self, metric: Metric) -> Option<Value> {
        self.values[metric as usize]
    }

    /// The value of `metric` as a number (see [`Value::as_f64`]).
    pub fn real(&self, metric: Metric) -> Option<f64> {
        self.get(metric).map(Value::as_f64)
    }

    /// Every table entry with its value, in table order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static MetricDef, Option<Value>)> + '_ {
        TABLE.iter().zip(self.values.iter().copied())
    }

    /// The affine rank of the wrenches.
    pub fn rank(&self) -> usize {
        match self.get(Metric::Rank) {
            Some(Value::Count(n)) => n as usize,
            _ => 0,
        }
    }

    /// The origin is strictly inside the wrench hull.
    pub fn force_closure(&self) -> bool {
        matches!(self.get(Metric::ForceClosure), Some(Value::Flag(true)))
    }

    /// The Largest Sphere radius, 0 without force closure.
    pub fn epsilon(&self) -> f64 {
        self.real(Metric::Epsilon).unwrap_or(0.0)
    }

    /// The Grasp Wrench Volume, `None` when not asked for.
    pub fn volume(&self) -> Option<f64> {
        self.real(Metric::Volume)
    }

    /// The distance from the origin to the wrench hull.
    pub fn distance(&self) -> f64 {
        self.real(Metric::Distance).unwrap_or(0.0)
    }

    /// The Bimodal Wrench metric.
    pub fn bw(&self) -> f64 {
        self.real(Metric::Bw).unwrap_or(0.0)
    }
}

impl Serialize for Value {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Value::Count(n) => s.serialize_u32(n),
            Value::Flag(b) => s.serialize_bool(b),
            Value::Real(x) => s.serialize_f64(x),
        }
    }
}

impl Serialize for Metrics {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(COUNT))?;
        for (def, value) in self.iter() {
            map.serialize_entry(def.key, &value)?;
        }
        map.end()
    }
}

/// A value as a self-describing format (JSON) writes it.
#[derive(Debug, Clone, Copy)]
enum Written {
    Flag(bool),
    Whole(u64),
    Number(f64),
}

impl Written {
    /// The value as the kind of its metric: a whole number where a real is expected is
    /// that real; anything else that does not fit is `None`.
    fn as_kind(self, kind: Kind) -> Option<Value> {
        match (kind, self) {
            (Kind::Flag, Written::Flag(b)) => Some(Value::Flag(b)),
            (Kind::Count, Written::Whole(n)) => u32::try_from(n).ok().map(Value::Count),
            (Kind::Real, Written::Whole(n)) => Some(Value::Real(n as f64)),
            (Kind::Real, Written::Number(x)) => Some(Value::Real(x)),
            _ => None,
        }
    }
}

impl<'de> Deserialize<'de> for Written {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Any;
        impl Visitor<'_> for Any {
            type Value = Written;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number or a boolean")
            }
            fn visit_bool<E>(self, b: bool) -> Result<Written, E> {
                Ok(Written::Flag(b))
            }
            fn visit_u64<E>(self, n: u64) -> Result<Written, E> {
                Ok(Written::Whole(n))
            }
            fn visit_i64<E>(self, n: i64) -> Result<Written, E> {
                Ok(u64::try_from(n).map_or(Written::Number(n as f64), Written::Whole))
            }
            fn visit_f64<E>(self, x: f64) -> Result<Written, E> {
                Ok(Written::Number(x))
            }
        }
        d.deserialize_any(Any)
    }
}

impl<'de> Deserialize<'de> for Metrics {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ByKey;
        impl<'de> Visitor<'de> for ByKey {
            type Value = Metrics;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an object of metric values by key")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Metrics, A::Error> {
                let mut metrics = Metrics::default();
                while let Some(key) = map.next_key::<String>()? {
                    let Some(metric) = Metric::from_key(&key) else {
                        // Not a metric (or one of a later graspopt).
                        map.next_value::<serde::de::IgnoredAny>()?;
                        continue;
                    };
                    let written = map.next_value::<Option<Written>>()?;
                    let kind = metric.def().kind;
                    metrics.values[metric as usize] = match written {
                        None => None,
                        Some(w) => Some(w.as_kind(kind).ok_or_else(|| {
                            serde::de::Error::custom(format_args!(
                                "metric {key}: {w:?} is not a {kind:?} value"
                            ))
                        })?),
                    };
                }
                Ok(metrics)
            }
        }
        d.deserialize_map(ByKey)
    }
}
