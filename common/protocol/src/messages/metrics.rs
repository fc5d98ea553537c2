//! A trial's grasp-quality metrics as results carry them ([`MetricValues`]).
//!
//! The protocol does not list the metrics: the values are named by their keys, in the
//! order of the metric table of `graspopt-quality` (`metrics::TABLE`), which the sender
//! follows. A metric added to the table therefore needs no change here, and a receiver
//! ignores keys it does not know.
//!
//! In JSON a result's metrics are an object (`{"rank": 6, "force_closure": true,
//! "epsilon": 0.12, "volume": null, ...}`); in bincode, the sequence of (key, value) pairs.

use serde::de::{MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::{Problem, ValidationError};

/// At most this many metric values in one result.
pub const MAX_METRICS: usize = 64;
/// At most this many bytes in a metric's key.
pub const MAX_METRIC_KEY: usize = 64;
// The validation's texts say both limits in words (`Problem` holds static text).
const _: () = assert!(MAX_METRICS == 64 && MAX_METRIC_KEY == 64);

/// One metric's value: a count, a flag or a real number.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum MetricValue {
    Count(u32),
    Flag(bool),
    Real(f64),
}

impl MetricValue {
    /// The value as a number: a count as itself, a flag as 0 or 1.
    pub fn as_f64(self) -> f64 {
        match self {
            MetricValue::Count(n) => f64::from(n),
            MetricValue::Flag(b) => f64::from(u8::from(b)),
            MetricValue::Real(x) => x,
        }
    }
}

/// The grasp-quality metrics of a trial (thesis chapter 2): each metric's key and value
/// (`None`: not computed, as the volume unless the score is the volume), in table order as
/// sent. Equal when the same metrics have the same values, in any order (a JSON decoder may
/// reorder an object's keys), a metric not computed (`None`) being the same as one absent.
#[derive(Debug, Clone, Default)]
pub struct MetricValues {
    values: Vec<(String, Option<MetricValue>)>,
}

impl PartialEq for MetricValues {
    fn eq(&self, other: &Self) -> bool {
        let within =
            |a: &Self, b: &Self| a.values.iter().all(|(k, v)| v.is_none() || b.get(k) == *v);
        within(self, other) && within(other, self)
    }
}

impl MetricValues {
    /// Metrics from (key, value) pairs, in table order.
    pub fn new(values: Vec<(String, Option<MetricValue>)>) -> Self {
        MetricValues { values }
    }

    /// Adds the value of `key` at the end.
    pub fn with(mut self, key: &str, value: Option<MetricValue>) -> Self {
        self.values.push((key.to_string(), value));
        self
    }

    /// Sets the value of `key`, appending it if it is not there.
    pub fn set(&mut self, key: &str, value: Option<MetricValue>) {
        match self.values.iter_mut().find(|(k, _)| k == key) {
            Some((_, v)) => *v = value,
            None => self.values.push((key.to_string(), value)),
        }
    }

    /// Every (key, value), in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, Option<MetricValue>)> {
        self.values.iter().map(|(k, v)| (k.as_str(), *v))
    }

    /// The value of the metric `key` (`None`: absent or not computed).
    pub fn get(&self, key: &str) -> Option<MetricValue> {
        self.values
            .iter()
            .find(|(k, _)| k == key)
            .and_then(|(_, v)| *v)
    }

    /// The value of `key` as a number (see [`MetricValue::as_f64`]).
    pub fn real(&self, key: &str) -> Option<f64> {
        self.get(key).map(MetricValue::as_f64)
    }

    /// The value of `key` if it is a flag.
    pub fn flag(&self, key: &str) -> Option<bool> {
        match self.get(key) {
            Some(MetricValue::Flag(b)) => Some(b),
            _ => None,
        }
    }

    /// The value of `key` if it is a count.
    pub fn count(&self, key: &str) -> Option<u32> {
        match self.get(key) {
            Some(MetricValue::Count(n)) => Some(n),
            _ => None,
        }
    }

    /// At most [`MAX_METRICS`] values, keys of 1 to [`MAX_METRIC_KEY`] bytes, every real
    /// finite; an error names the metric (`metrics.bw is not finite (NaN)`).
    pub fn validate(&self, field: &str) -> Result<(), ValidationError> {
        self.validate_in("MetricValues", field)
    }

    /// [`MetricValues::validate`] inside a message of type `message_type`.
    pub fn validate_in(
        &self,
        message_type: &'static str,
        field: &str,
    ) -> Result<(), ValidationError> {
        if self.values.len() > MAX_METRICS {
            return Err(ValidationError::new(
                message_type,
                field,
                Problem::OutOfRange {
                    requirement: "at most 64 values",
                    value: self.values.len() as f64,
                },
            ));
        }
        for (key, value) in &self.values {
            if key.is_empty() || key.len() > MAX_METRIC_KEY {
                return Err(ValidationError::new(
                    message_type,
                    format!("{field} key {key:?}"),
                    Problem::Unmet("of 1 to 64 bytes"),
                ));
            }
            if let Some(MetricValue::Real(x)) = value
                && !x.is_finite()
            {
                return Err(ValidationError::new(
                    message_type,
                    format!("{field}.{key}"),
                    Problem::NotFinite(*x),
                ));
            }
        }
        Ok(())
    }
}

/// A value as JSON writes it: the bare number or boolean.
struct Bare(MetricValue);

impl Serialize for Bare {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0 {
            MetricValue::Count(n) => s.serialize_u32(n),
            MetricValue::Flag(b) => s.serialize_bool(b),
            MetricValue::Real(x) => s.serialize_f64(x),
        }
    }
}

impl<'de> Deserialize<'de> for Bare {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Any;
        impl Visitor<'_> for Any {
            type Value = Bare;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number or a boolean")
            }
            fn visit_bool<E>(self, b: bool) -> Result<Bare, E> {
                Ok(Bare(MetricValue::Flag(b)))
            }
            fn visit_u64<E>(self, n: u64) -> Result<Bare, E> {
                Ok(Bare(
                    u32::try_from(n).map_or(MetricValue::Real(n as f64), MetricValue::Count),
                ))
            }
            fn visit_i64<E>(self, n: i64) -> Result<Bare, E> {
                Ok(Bare(match u32::try_from(n) {
                    Ok(n) => MetricValue::Count(n),
                    Err(_) => MetricValue::Real(n as f64),
                }))
            }
            fn visit_f64<E>(self, x: f64) -> Result<Bare, E> {
                Ok(Bare(MetricValue::Real(x)))
            }
        }
        d.deserialize_any(Any)
    }
}

impl Serialize for MetricValues {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if s.is_human_readable() {
            let mut map = s.serialize_map(Some(self.values.len()))?;
            for (key, value) in &self.values {
                map.serialize_entry(key, &value.map(Bare))?;
            }
            map.end()
        } else {
            let mut seq = s.serialize_seq(Some(self.values.len()))?;
            for pair in &self.values {
                seq.serialize_element(pair)?;
            }
            seq.end()
        }
    }
}

impl<'de> Deserialize<'de> for MetricValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Pairs;
        impl<'de> Visitor<'de> for Pairs {
            type Value = MetricValues;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("metric values by key")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<MetricValues, A::Error> {
                let mut values = Vec::new();
                while let Some((key, value)) = map.next_entry::<String, Option<Bare>>()? {
                    too_many::<A::Error>(values.len())?;
                    values.push((key, value.map(|b| b.0)));
                }
                Ok(MetricValues { values })
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<MetricValues, A::Error> {
                let mut values = Vec::new();
                while let Some(pair) = seq.next_element::<(String, Option<MetricValue>)>()? {
                    too_many::<A::Error>(values.len())?;
                    values.push(pair);
                }
                Ok(MetricValues { values })
            }
        }
        if d.is_human_readable() {
            d.deserialize_map(Pairs)
        } else {
            d.deserialize_seq(Pairs)
        }
    }
}

/// Refuses a value beyond [`MAX_METRICS`] while decoding (before it is allocated).
fn too_many<E: serde::de::Error>(read: usize) -> Result<(), E> {
    if read >= MAX_METRICS {
        Err(E::custom(format_args!(
            "more than {MAX_METRICS} metric values"
        )))
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> MetricValues {
        MetricValues::default()
            .with("rank", Some(MetricValue::Count(6)))
            .with("force_closure", Some(MetricValue::Flag(true)))
            .with("epsilon", Some(MetricValue::Real(0.25)))
            .with("volume", None)
    }

    #[test]
    fn json_is_an_object_in_order_and_reads_back() {
        let m = sample();
        let text = serde_json::to_string(&m).unwrap();
        assert_eq!(
            text,
            r#"{"rank":6,"force_closure":true,"epsilon":0.25,"volume":null}"#
        );
        assert_eq!(serde_json::from_str::<MetricValues>(&text).unwrap(), m);
        assert_eq!(m.real("epsilon"), Some(0.25));
        assert_eq!(
            (m.flag("force_closure"), m.count("rank")),
            (Some(true), Some(6))
        );
        assert_eq!((m.get("volume"), m.get("isotropy")), (None, None));
    }

    #[test]
    fn bincode_round_trips_and_validation_names_the_metric() {
        let config = bincode::config::standard();
        let m = sample();
        let bytes = bincode::serde::encode_to_vec(&m, config).unwrap();
        let (back, _): (MetricValues, usize) =
            bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(back, m);
        assert!(m.validate("metrics").is_ok());
        let bad = m.with("bw", Some(MetricValue::Real(f64::NAN)));
        assert_eq!(
            bad.validate("metrics").unwrap_err().to_string(),
            "metrics.bw is not finite (NaN)"
        );
    }
}
