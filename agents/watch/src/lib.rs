//! Watches a graspopt bus from a terminal: the library behind `graspopt topic` and
//! `graspopt monitor`.
//!
//! - [`topic`]: topic rows of the live agents, echo formatting, rate and bandwidth windows, and
//!   the loops that list, echo and measure a topic.
//! - [`monitor`]: what the monitor knows of each run, its text and its dashboard (ratatui),
//!   and the loops that fill them from the bus.
//!
//! The functions take plain settings and a `stop` future (Ctrl-C in the binary, a timer in
//! tests), never command-line flags. This crate only reads the bus: it must not know how the
//! agents decide.
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod monitor;
pub mod topic;

/// `name=value` for each parameter (5 decimals), joined by `sep`.
pub fn named_params(names: &[String], values: &[f64], sep: &str) -> String {
    let parts: Vec<String> = names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n}={v:.5}"))
        .collect();
    parts.join(sep)
}

#[cfg(test)]
mod tests {
    #[test]
    fn named_params_pairs_names_and_values() {
        let names = ["a".to_string(), "b".to_string()];
        assert_eq!(
            super::named_params(&names, &[0.5, -1.0], ","),
            "a=0.50000,b=-1.00000"
        );
    }
}
