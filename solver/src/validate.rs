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

/// Checks that `value` is finite and strictly positive, naming `field` otherwise.
pub fn positive(field: &str, value: f64) -> Result<f64, SolverError> {
    if finite(field, value)? > 0.0 {
        Ok(value)
    } else {
        Err(SolverError::input(field, format!("{field} must be greater than 0 (got {value})")))
    }
}

/// Checks that `value` is finite and not negative, naming `field` otherwise.
pub fn non_negative(field: &str, value: f64) -> Result<f64, SolverError> {
    if finite(field, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(SolverError::input(field, format!("{field} must not be negative (got {value})")))
    }
}

/// Checks that `value` is finite and within ±`limit`, naming `field` otherwise.
pub fn within(field: &str, value: f64, limit: f64) -> Result<f64, SolverError> {
    if finite(field, value)?.abs() > limit {
        return Err(SolverError::input(
            field,
            format!("{field} must lie within ±{limit} mm (got {} mm)", quoted(value)),
        ));
    }
    Ok(value)
}

/// A number as a refusal quotes it: in exponent form when huge, so that 1e308 is not written out
/// in 309 digits.
pub fn quoted(value: f64) -> String {
    if value.abs() >= 1e15 { format!("{value:e}") } else { format!("{value}") }
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
pub fn positive_at_most(field: &str, value: f64, limit: f64) -> Result<f64, SolverError> {
    if positive(field, value)? > limit {
        return Err(SolverError::input(field, format!("{field} must be at most {limit} (got {value})")));
    }
    Ok(value)
}

/// `value` if given (then positive), else `default`.
pub fn optional_positive(field: &str, value: Option<f64>, default: f64) -> Result<f64, SolverError> {
    value.map_or(Ok(default), |v| positive(field, v))
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
