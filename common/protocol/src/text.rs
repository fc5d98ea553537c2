//! How the tools show numbers to people. JSON and CSV keep every digit; a line
//! a person reads rounds.

/// Significant digits of a number a person reads (a score, say).
pub const SHOWN_DIGITS: i32 = 5;

/// `v` with [`SHOWN_DIGITS`] significant digits (`0.20025899065118113` is `0.20026`,
/// `0.000123456` is `0.00012346`, `1234567.8` is `1234568`); zero and non-finite values as
/// they are.
pub fn rounded(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor() as i32;
    // The leading digit after rounding: 9.99996 rounds to 10.000, one digit more to the left.
    let magnitude =
        if (v.abs() / 10f64.powi(magnitude)) >= 10.0 - 0.5 * 10f64.powi(1 - SHOWN_DIGITS) {
            magnitude + 1
        } else {
            magnitude
        };
    let decimals = (SHOWN_DIGITS - 1 - magnitude).max(0) as usize;
    format!("{v:.decimals$}")
}

/// `n` with its digits in groups of three (`1,000,000,000`).
pub fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, d) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(d);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{grouped, rounded};

    #[test]
    fn thousands_are_grouped() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(1000), "1,000");
        assert_eq!(grouped(1_000_000_000), "1,000,000,000");
        assert_eq!(grouped(u64::MAX), "18,446,744,073,709,551,615");
    }

    #[test]
    fn five_significant_digits() {
        assert_eq!(rounded(0.20025899065118113), "0.20026");
        assert_eq!(rounded(0.17070), "0.17070");
        assert_eq!(rounded(-0.000123456), "-0.00012346");
        assert_eq!(rounded(1.0), "1.0000");
        assert_eq!(rounded(12.345678), "12.346");
        assert_eq!(rounded(1234567.8), "1234568");
        assert_eq!(rounded(9.99996), "10.000");
        assert_eq!(rounded(0.0999996), "0.10000");
        assert_eq!(rounded(0.0), "0");
        assert_eq!(rounded(f64::NAN), "NaN");
    }
}
