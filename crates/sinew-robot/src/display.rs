//! Numbers in messages: compact, whatever their size.

use std::fmt;

/// A number for an error message or a label: at most `precision` significant digits
/// (default 5), in scientific notation when its magnitude is below `1e-3` or at least `1e6`,
/// so a huge load prints as `1.0000e300`, not as 300 digits. NaN and infinities print as Rust
/// prints them.
///
/// ```
/// use sinew_robot::Compact;
/// assert_eq!(Compact(0.3).to_string(), "0.3");
/// assert_eq!(Compact(-1.0 / 3.0).to_string(), "-0.33333");
/// assert_eq!(Compact(2.5e300).to_string(), "2.5e300");
/// assert_eq!(Compact(1.0e-7).to_string(), "1e-7");
/// assert_eq!(Compact(600.0).to_string(), "600");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compact(pub f64);

/// Significant digits of [`Compact`].
const DIGITS: usize = 5;

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if !x.is_finite() {
            return write!(f, "{x}");
        }
        if x == 0.0 {
            return f.write_str("0");
        }
        let magnitude = x.abs();
        if !(1e-3..1e6).contains(&magnitude) {
            let text = format!("{:.*e}", DIGITS - 1, x);
            // Trim trailing zeros of the mantissa: 2.5000e300 -> 2.5e300.
            return match text.split_once('e') {
                Some((mantissa, exponent)) => {
                    write!(f, "{}e{exponent}", trim_zeros(mantissa))
                }
                None => f.write_str(&text),
            };
        }
        let integer_digits = magnitude.log10().floor() as i32 + 1;
        let decimals = (DIGITS as i32 - integer_digits).max(0) as usize;
        let text = format!("{x:.decimals$}");
        let text = trim_zeros(&text);
        if text == "-0" { f.write_str("0") } else { f.write_str(text) }
    }
}

/// `1.2300` -> `1.23`, `600.000` -> `600`; integers untouched.
fn trim_zeros(text: &str) -> &str {
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.') } else { text }
}
