//! A trial point as users write it: `x=-0.08,y=0.01` (parameter names as
//! [`ParamKind::parse`] reads them; metres, radians for rx, ry, rz), checked against a
//! trial space with messages that keep numbers short.

use graspopt_sim::pose::short as compact_bound;
use graspopt_sim::{ParamKind, TrialSpace};

use crate::error::TrialError;

/// The parameters a user named and their values, in the order given.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NamedPoint {
    /// The names as written (trimmed).
    pub names: Vec<String>,
    pub kinds: Vec<ParamKind>,
    pub values: Vec<f64>,
}

fn bad(message: String) -> TrialError {
    TrialError::Settings(message)
}

impl NamedPoint {
    /// Parses `NAME=VALUE,...` (empty: no parameter). A name given twice, a value that is
    /// not a finite number, or a missing `=` is an error naming it.
    pub fn parse(text: &str) -> Result<NamedPoint, TrialError> {
        let mut p = NamedPoint::default();
        for part in text.split(',').filter(|p| !p.trim().is_empty()) {
            let (name, value) = part
                .split_once('=')
                .ok_or_else(|| bad(format!("expected NAME=VALUE, got {part:?}")))?;
            let name = name.trim();
            let kind = ParamKind::parse(name)?;
            if p.kinds.contains(&kind) {
                return Err(bad(format!("{} given twice", kind.name())));
            }
            let value: f64 = value
                .trim()
                .parse()
                .map_err(|_| bad(format!("{name} is not a number: {value:?}")))?;
            if !value.is_finite() {
                let named = described(name, kind);
                return Err(bad(format!("{named} = {value} is not a finite number")));
            }
            p.names.push(name.to_string());
            p.kinds.push(kind);
            p.values.push(value);
        }
        Ok(p)
    }

    /// Checks every value against `space`'s bounds (the simulator's own slack, so exact
    /// bounds pass); `object` names the object in the message, which also says how to set
    /// other bounds.
    pub fn check_within(&self, space: &TrialSpace, object: &str) -> Result<(), TrialError> {
        for (((name, kind), value), (lo, hi)) in self
            .names
            .iter()
            .zip(&self.kinds)
            .zip(&self.values)
            .zip(space.bounds())
        {
            if *value < lo - 1e-9 || *value > hi + 1e-9 {
                let (min, max) = kind.limits();
                return Err(bad(format!(
                    "{} = {} is outside [{}, {}] {} for the {object} (--range {}=LO:HI sets \
                     other bounds, within {}:{})",
                    described(name, *kind),
                    compact(*value),
                    compact_bound(lo),
                    compact_bound(hi),
                    kind.unit(),
                    kind.name(),
                    compact_bound(min),
                    compact_bound(max),
                )));
            }
        }
        Ok(())
    }
}

/// A value for a message: as given when that is short, else `1.0000e300`.
fn compact(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 12 {
        plain
    } else {
        format!("{v:.4e}")
    }
}

/// A parameter as the user named it, with its full name when that differs: `x (approach)`.
fn described(name: &str, kind: ParamKind) -> String {
    let full = kind.name();
    if name == full {
        name.to_string()
    } else {
        format!("{name} ({full})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(compact(1e300), "1.0000e300");
        assert_eq!(compact(-0.08), "-0.08");
        assert_eq!(compact(0.020_000_1), "0.0200001");
        assert_eq!(compact_bound(-std::f64::consts::FRAC_PI_4), "-0.7854");
        assert_eq!(compact_bound(0.02), "0.02");
        assert_eq!(compact_bound(0.0), "0");
        assert_eq!(compact_bound(1e-7), "1.0000e-7");
    }

    #[test]
    fn a_point_parses_in_order_and_bad_ones_are_named() {
        let p = NamedPoint::parse(" x=-0.08, rz=0.5,").unwrap();
        assert_eq!(p.names, ["x", "rz"]);
        assert_eq!(p.kinds, [ParamKind::Approach, ParamKind::RotZ]);
        assert_eq!(p.values, [-0.08, 0.5]);
        assert_eq!(NamedPoint::parse("").unwrap(), NamedPoint::default());
        for (text, message) in [
            ("x", "expected NAME=VALUE, got \"x\""),
            ("x=1,approach=2", "approach given twice"),
            ("x=abc", "x is not a number: \"abc\""),
            ("y=inf", "y (vertical) = inf is not a finite number"),
        ] {
            let e = NamedPoint::parse(text).unwrap_err().to_string();
            assert_eq!(e, message, "{text}");
        }
    }

    #[test]
    fn values_outside_the_space_are_refused_with_its_bounds() {
        let o = graspopt_sim::Object::by_name("sphere").unwrap();
        let space = TrialSpace::with_params(&o, &[ParamKind::RotX]).unwrap();
        let (lo, hi) = space.bounds()[0];
        NamedPoint::parse(&format!("rx={hi}"))
            .unwrap()
            .check_within(&space, "sphere")
            .unwrap();
        let e = NamedPoint::parse(&format!("roll={}", lo - 1.0))
            .unwrap()
            .check_within(&space, "sphere")
            .unwrap_err()
            .to_string();
        let expected = format!(
            "roll (rx) = {} is outside [{}, {}] rad for the sphere (--range rx=LO:HI sets other \
             bounds, within -1.5708:1.5708)",
            compact(lo - 1.0),
            compact_bound(lo),
            compact_bound(hi)
        );
        assert_eq!(e, expected);
    }
}
