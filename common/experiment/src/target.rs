//! How soon a run gets near a reference value (the grid maximum in 2D, the best value any
//! run found in 6D), the way thesis Table 4.1 counts it.

/// The fractions of Table 4.1: within 5%, 10% and 20% of the reference.
pub const TARGET_FRACTIONS: [f64; 3] = [0.05, 0.10, 0.20];

/// Trials (1-based) until the best value so far is within `fraction` of `reference`, that is
/// at least `reference - fraction * |reference|`; None if never.
pub fn trials_to_within(best_so_far: &[f64], reference: f64, fraction: f64) -> Option<usize> {
    let goal = reference - fraction * reference.abs();
    best_so_far.iter().position(|b| *b >= goal).map(|i| i + 1)
}

/// Median (mean of the two middle values for an even count); `None` when empty: the
/// engine crate's, the one copy in the workspace.
pub use graspopt_bayesopt::benchmark::median;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_trials_to_a_fraction_of_positive_and_negative_references() {
        let best = [-3.0, 0.5, 0.85, 0.96, 1.0];
        assert_eq!(trials_to_within(&best, 1.0, 0.05), Some(4));
        assert_eq!(trials_to_within(&best, 1.0, 0.20), Some(3));
        assert_eq!(trials_to_within(&best, 1.0, 0.0), Some(5));
        assert_eq!(trials_to_within(&best[..3], 1.0, 0.05), None);
        // a negative reference: within 10% of -2 means at least -2.2
        assert_eq!(trials_to_within(&[-3.0, -2.3, -2.1], -2.0, 0.10), Some(3));
        assert_eq!(trials_to_within(&[], 1.0, 0.05), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
