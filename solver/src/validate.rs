//! Field-path validation shared by every capability's request: finite, positive and bounded
//! numbers and points, each refusal an `E_INPUT` naming the field as written in the request
//! (`hole.radius`, `stock.polygon[3][1]`).

use crate::error::SolverError;

/// Largest coordinate, length or radius accepted in any request's geometry, mm (100 m: beyond the
/// travel of any machine tool, and far enough from the float range that squares, cross products
/// and the bisections of every solver stay finite and exact enough). Every endpoint checks its
/// geometry with [`coordinate`] or [`point`] against it, so one range holds everywhere.
pub const MAX_COORDINATE: f64 = 1e5;

/// Checks that `value` is a finite number, naming `field` otherwise.
pub fn finite(field: &str, value: f64) -> Result<f64, SolverError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SolverError::input(field, format!("{field} must be a finite number")))
    }
}

/// What a checked value measures, so that its refusal quotes it with its unit. Every request is
/// checked in mm, once converted; a length or feed quoted with its unit is restated in the
/// request's units at the edge (`Scaling::restate`), one quoted bare would reach an inch request
/// as a number of millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// A count, ratio, time, speed in rpm or other value no conversion of units touches.
    Number,
    /// A length, mm.
    Length,
    /// A feed, mm/min.
    Feed,
    /// A feed per tooth, mm/tooth.
    FeedPerTooth,
}

impl Measure {
    /// `value` as a refusal quotes it, followed by its unit.
    pub fn quote(self, value: f64) -> String {
        let unit = match self {
            Self::Number => "",
            Self::Length => " mm",
            Self::Feed => " mm/min",
            Self::FeedPerTooth => " mm/tooth",
        };
        format!("{}{unit}", quoted(value))
    }
}

/// Checks that `value` is finite and strictly positive, naming `field` otherwise.
pub fn positive(field: &str, value: f64, measure: Measure) -> Result<f64, SolverError> {
    if finite(field, value)? > 0.0 {
        Ok(value)
    } else {
        Err(SolverError::input(field, format!("{field} must be greater than 0 (got {})", measure.quote(value))))
    }
}

/// Checks that `value` is finite and not negative, naming `field` otherwise.
pub fn non_negative(field: &str, value: f64, measure: Measure) -> Result<f64, SolverError> {
    if finite(field, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(SolverError::input(field, format!("{field} must not be negative (got {})", measure.quote(value))))
    }
}

/// Checks that `value` is finite and within ±`limit`, naming `field` otherwise.
pub fn within(field: &str, value: f64, limit: f64) -> Result<f64, SolverError> {
    if finite(field, value)?.abs() > limit {
        return Err(SolverError::input(
            field,
            format!("{field} must lie within ±{} (got {})", Measure::Length.quote(limit), Measure::Length.quote(value)),
        ));
    }
    Ok(value)
}

/// A number as a refusal quotes it: to 12 significant digits, so that a value converted from
/// inches reads as given (-3 in is -76.2 mm, not -76.19999999999999), and in exponent form when
/// huge or tiny, so that 1e308 is not written out in 309 digits.
pub fn quoted(value: f64) -> String {
    let rounded: f64 = format!("{value:.11e}").parse().unwrap_or(value);
    if rounded != 0.0 && !(1e-9..1e15).contains(&rounded.abs()) { format!("{rounded:e}") } else { format!("{rounded}") }
}

/// Checks that a coordinate is finite and within ±[`MAX_COORDINATE`], naming `field` otherwise: the
/// one range of every request's geometry.
pub fn coordinate(field: &str, value: f64) -> Result<f64, SolverError> {
    within(field, value, MAX_COORDINATE)
}

/// Checks every coordinate of a point is finite and within ±[`MAX_COORDINATE`], naming
/// `field[axis]`.
pub fn coordinates<const N: usize>(field: &str, value: [f64; N]) -> Result<[f64; N], SolverError> {
    point(field, value, MAX_COORDINATE)
}

/// Checks that `value` is positive and at most `limit`, naming `field` otherwise.
pub fn positive_at_most(field: &str, value: f64, limit: f64, measure: Measure) -> Result<f64, SolverError> {
    if positive(field, value, measure)? > limit {
        return Err(SolverError::input(
            field,
            format!("{field} must be at most {} (got {})", measure.quote(limit), measure.quote(value)),
        ));
    }
    Ok(value)
}

/// `value` if given (then positive), else `default`.
pub fn optional_positive(field: &str, value: Option<f64>, default: f64, measure: Measure) -> Result<f64, SolverError> {
    value.map_or(Ok(default), |v| positive(field, v, measure))
}

/// Checks every coordinate of `point` is finite and within ±`limit`, naming `field[axis]`.
pub fn point<const N: usize>(field: &str, point: [f64; N], limit: f64) -> Result<[f64; N], SolverError> {
    for (axis, value) in point.iter().enumerate() {
        // The name is formatted only for a refusal: long point lists are checked by the
        // thousand.
        if !(value.is_finite() && value.abs() <= limit) {
            within(&format!("{field}[{axis}]"), *value, limit)?;
        }
    }
    Ok(point)
}

/// A name or description of at most `max_chars` characters without control characters (NUL, CR,
/// LF, tab…): such text goes into G-code comments and headers, where a line break would start a
/// new block.
///
/// # Errors
/// `E_INPUT` at `field` for a control character or text over `max_chars`.
pub fn text<'a>(field: &str, value: &'a str, max_chars: usize) -> Result<&'a str, SolverError> {
    if value.chars().count() > max_chars {
        return Err(SolverError::input(field, format!("{field} must be at most {max_chars} characters")));
    }
    if let Some(control) = value.chars().find(|c| c.is_control()) {
        return Err(SolverError::input(
            field,
            format!("{field} must not contain control characters (found U+{:04X})", u32::from(control)),
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::{Measure, positive, quoted};

    #[test]
    fn a_quoted_value_reads_as_given_in_its_unit() {
        // -3 in converted to mm.
        assert_eq!(quoted(-3.0 * 25.4), "-76.2");
        assert_eq!(quoted(0.1 + 0.2), "0.3");
        assert_eq!(quoted(1e308), "1e308");
        assert_eq!(quoted(2e-300), "2e-300");
        assert_eq!(quoted(0.0), "0");
        assert_eq!(Measure::Feed.quote(-76.2), "-76.2 mm/min");
        let refused = positive("feed", -3.0 * 25.4, Measure::Feed).unwrap_err();
        assert_eq!(refused.message(), "feed must be greater than 0 (got -76.2 mm/min)");
        let refused = positive("spindle_rpm", -3.0, Measure::Number).unwrap_err();
        assert_eq!(refused.message(), "spindle_rpm must be greater than 0 (got -3)");
    }
}
