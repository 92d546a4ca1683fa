//! The units a request is written in and its answer is given in (docs/spec/api.md, Units):
//! millimetres or inches for every length, mm/min or inch/min for every feed. The solvers compute
//! in millimetres only; a request in inches is converted once before it is solved and its answer
//! once after, each type listing its lengths and feeds in its [`Scale`] implementation. Angles,
//! times, spindle speeds, counts, forces and stiffnesses are not scaled.

use serde::{Deserialize, Serialize};

use crate::tool::{ShapeErrorPoint, Tool, ToolRef};

/// Millimetres in one inch, exactly.
pub const MM_PER_INCH: f64 = 25.4;

/// The units of lengths (and of feeds, per minute) in a request and its answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres, feeds in mm/min.
    #[default]
    Mm,
    /// Inches, feeds in inch/min; programs in G20 with 4 decimals (0.0001 in).
    Inch,
}

impl Units {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Inch => "inch",
        }
    }

    /// Millimetres in one of these units.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Self::Mm => 1.0,
            Self::Inch => MM_PER_INCH,
        }
    }

    /// The conversion of a request in these units into millimetres (`None` for millimetres).
    pub fn into_mm(self) -> Option<Scaling> {
        (self != Self::Mm).then_some(Scaling { mm_per_unit: self.mm_per_unit(), into_mm: true })
    }

    /// The conversion of an answer in millimetres into these units (`None` for millimetres).
    pub fn from_mm(self) -> Option<Scaling> {
        (self != Self::Mm).then_some(Scaling { mm_per_unit: self.mm_per_unit(), into_mm: false })
    }

    /// `value` in mm, given in these units (for messages that quote a request's value).
    pub fn of_mm(self, value_mm: f64) -> f64 {
        value_mm / self.mm_per_unit()
    }
}

/// Length units of a drawing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum DrawingUnits {
    /// Millimetres (`$INSUNITS` 4).
    Mm,
    /// Centimetres (5).
    Cm,
    /// Metres (6).
    M,
    /// Inches (1).
    Inch,
    /// Feet (2).
    Foot,
    /// Micrometres (13).
    Micron,
}

impl DrawingUnits {
    /// Millimetres per unit.
    pub fn scale(self) -> f64 {
        match self {
            Self::Mm => 1.0,
            Self::Cm => 10.0,
            Self::M => 1000.0,
            Self::Inch => 25.4,
            Self::Foot => 304.8,
            Self::Micron => 0.001,
        }
    }

    /// The units of an `$INSUNITS` value; `None` for unitless (0) and units kerf does not take.
    pub(crate) fn from_insunits(code: i64) -> Option<Self> {
        Some(match code {
            1 => Self::Inch,
            2 => Self::Foot,
            4 => Self::Mm,
            5 => Self::Cm,
            6 => Self::M,
            13 => Self::Micron,
            _ => return None,
        })
    }
}

/// One conversion of lengths: from the request's units into mm (multiplied by the millimetres
/// in a unit), or from mm into the answer's (divided by them, so 25.4 mm is exactly 1 inch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    mm_per_unit: f64,
    into_mm: bool,
}

impl Scaling {
    /// `value` converted.
    #[must_use]
    pub fn apply(self, value: f64) -> f64 {
        if self.into_mm { value * self.mm_per_unit } else { value / self.mm_per_unit }
    }

    /// The units other than mm this conversion is from or into.
    pub fn units(self) -> Units {
        if self.mm_per_unit == MM_PER_INCH { Units::Inch } else { Units::Mm }
    }

    /// `text` (a warning, a refusal's detail, a program's comment) written in mm, restated in the
    /// units of this conversion's answer: every number followed by `mm`, `mm/min`, `mm/tooth`,
    /// `mm²` or `mm³` is converted and followed by `in`, `in/min`, `in/tooth`, `in²` or `in³`, and
    /// a unit named alone in parentheses, `(mm)`, `(mm/min)`, `(mm/tooth)`, is renamed. The
    /// solvers write every length and feed of a message with its unit after it, so this one
    /// rewrite at the edge restates them all. A conversion into mm leaves the text as it is.
    #[must_use]
    pub fn restate(self, text: &str) -> String {
        if self.into_mm || self.units() == Units::Mm {
            return text.to_owned();
        }
        restate_in(text, self.mm_per_unit)
    }
}

/// A unit of a message, after a number: its text in mm and in inches, and the power of the length
/// it holds (feeds per minute and per tooth are lengths).
type MessageUnit = (&'static str, &'static str, i32);

/// The units a message's numbers may carry, longest first where one begins another.
const MESSAGE_UNITS: [MessageUnit; 5] =
    [("mm/min", "in/min", 1), ("mm/tooth", "in/tooth", 1), ("mm²", "in²", 2), ("mm³", "in³", 3), ("mm", "in", 1)];

/// Fewest decimals of a length restated in inches: 0.0001 in, the programs' step.
const INCH_DECIMALS: usize = 4;

/// [`Scaling::restate`] for inches of `mm_per_unit` millimetres.
fn restate_in(text: &str, mm_per_unit: f64) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut rest = text;
    while !rest.is_empty() {
        if let Some((number, unit, used)) = number_with_unit(rest) {
            let (value, digits) = number;
            let value = value / mm_per_unit.powi(unit.2);
            let decimals =
                decimals_for(value, digits, if unit.2 == 1 && unit.0 != "mm/min" { INCH_DECIMALS } else { 1 });
            out.push_str(&format!("{value:.decimals$} {}", unit.1));
            rest = &rest[used..];
            continue;
        }
        if let Some(renamed) = ["(mm/min)", "(mm/tooth)", "(mm)"].iter().find(|name| rest.starts_with(**name)) {
            out.push_str(&renamed.replace("mm", "in"));
            rest = &rest[renamed.len()..];
            continue;
        }
        // Copy up to the start of the next token (a digit or sign after a non-word character, or
        // an opening parenthesis) in one step.
        let mut chars = rest.char_indices();
        let (_, first) = chars.next().expect("not empty");
        let mut end = first.len_utf8();
        if first.is_alphanumeric() || first == '_' || first == '.' {
            // Inside a word or a number that is not a length: to the word's end.
            for (index, c) in chars {
                if !(c.is_alphanumeric() || c == '_' || c == '.') {
                    break;
                }
                end = index + c.len_utf8();
            }
        }
        out.push_str(&rest[..end]);
        rest = &rest[end..];
    }
    out
}

/// The decimals that give `value` the significant `digits` its mm text had (at least 4, at most
/// 8 of them), never fewer than `least` nor more than 12.
fn decimals_for(value: f64, digits: usize, least: usize) -> usize {
    let digits = digits.clamp(4, 8) as i32;
    let magnitude = if value == 0.0 { 0 } else { value.abs().log10().floor() as i32 };
    usize::try_from(digits - 1 - magnitude).unwrap_or(0).clamp(least, 12)
}

/// A number at the start of `text` followed by a unit of [`MESSAGE_UNITS`] (one space or none
/// between, the unit not running on into a word): the number's value and significant digits, the
/// unit, and the bytes they take.
fn number_with_unit(text: &str) -> Option<((f64, usize), MessageUnit, usize)> {
    let bytes = text.as_bytes();
    let mut end = 0;
    if matches!(bytes.first(), Some(b'-' | b'+')) {
        end = 1;
    }
    let start_digits = end;
    let mut digits = 0;
    let mut leading = true;
    let mut seen_point = false;
    while let Some(&b) = bytes.get(end) {
        if b.is_ascii_digit() {
            // Leading zeros only place the digits.
            if b != b'0' || !leading {
                leading = false;
                digits += 1;
            }
            end += 1;
        } else if b == b'.' && !seen_point && bytes.get(end + 1).is_some_and(u8::is_ascii_digit) {
            seen_point = true;
            end += 1;
        } else {
            break;
        }
    }
    if end == start_digits || !bytes[start_digits].is_ascii_digit() {
        return None;
    }
    if matches!(bytes.get(end), Some(b'e' | b'E')) {
        let mut exponent = end + 1;
        if matches!(bytes.get(exponent), Some(b'-' | b'+')) {
            exponent += 1;
        }
        if bytes.get(exponent).is_some_and(u8::is_ascii_digit) {
            while bytes.get(exponent).is_some_and(u8::is_ascii_digit) {
                exponent += 1;
            }
            end = exponent;
        }
    }
    let value: f64 = text[..end].parse().ok()?;
    let after = &text[end..];
    let (gap, after) = match after.strip_prefix(' ') {
        Some(after) => (1, after),
        None => (0, after),
    };
    let unit = MESSAGE_UNITS.iter().find(|(mm, _, _)| {
        after.strip_prefix(mm).is_some_and(|tail| {
            tail.chars().next().is_none_or(|c| !(c.is_alphanumeric() || c == '_' || c == '/' || c == '²' || c == '³'))
        })
    })?;
    // A number written out in full f64 digits counts those it holds rounded to 12.
    let digits = if digits > 12 { written_digits(value) } else { digits };
    Some(((value, digits.max(1)), *unit, end + gap + unit.0.len()))
}

/// The significant digits of `value` rounded to 12 of them: a length converted from inches and
/// written out in full (-152.39999999999998 mm) has 5, as its inch value has.
fn written_digits(value: f64) -> usize {
    let mantissa = format!("{:.11e}", value.abs());
    let mantissa = mantissa.split('e').next().unwrap_or_default();
    mantissa.trim_end_matches('0').bytes().filter(u8::is_ascii_digit).count()
}

/// A value whose lengths and feeds are converted by a [`Scaling`]: each implementation lists
/// every length and feed field of its type (and only those), so none is missed or scaled twice.
pub trait Scale {
    /// Converts every length and feed in place.
    fn scale(&mut self, scaling: Scaling);
}

impl Scale for f64 {
    fn scale(&mut self, scaling: Scaling) {
        *self = scaling.apply(*self);
    }
}

impl<T: Scale> Scale for Option<T> {
    fn scale(&mut self, scaling: Scaling) {
        if let Some(value) = self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale> Scale for Vec<T> {
    fn scale(&mut self, scaling: Scaling) {
        for value in self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale, const N: usize> Scale for [T; N] {
    fn scale(&mut self, scaling: Scaling) {
        for value in self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale> Scale for Box<T> {
    fn scale(&mut self, scaling: Scaling) {
        (**self).scale(scaling);
    }
}

impl Scale for crate::geometry::Vec3 {
    fn scale(&mut self, scaling: Scaling) {
        self.x.scale(scaling);
        self.y.scale(scaling);
        self.z.scale(scaling);
    }
}

/// Lengths and feeds of a tool; `helix_deg`, `flutes` and the stiffness (N/mm) are not.
impl Scale for Tool {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            number: _,
            kind: _,
            radius,
            corner_radius,
            flutes: _,
            name: _,
            helix_deg: _,
            stickout,
            flute_length,
            plunge_feed,
            centre_cutting: _,
            neck_radius,
            neck_length,
            shank_radius,
            holder_diameter,
            holder_length,
            shape_error,
            stiffness: _,
        } = self;
        radius.scale(scaling);
        for value in [
            corner_radius,
            stickout,
            flute_length,
            plunge_feed,
            neck_radius,
            neck_length,
            shank_radius,
            holder_diameter,
            holder_length,
        ] {
            value.scale(scaling);
        }
        shape_error.scale(scaling);
    }
}

impl Scale for ShapeErrorPoint {
    fn scale(&mut self, scaling: Scaling) {
        self.error.scale(scaling);
    }
}

/// An inline tool is scaled; a tool-table number refers to a stored tool, which is in mm.
impl Scale for ToolRef {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Number(_) => {}
            Self::Inline(tool) => tool.scale(scaling),
        }
    }
}

/// A warning's message, restated in the answer's units.
impl Scale for crate::error::Warning {
    fn scale(&mut self, scaling: Scaling) {
        self.message = scaling.restate(&self.message);
    }
}

/// A sentence of an answer (a description, a note), restated in the answer's units.
impl Scale for String {
    fn scale(&mut self, scaling: Scaling) {
        *self = scaling.restate(self);
    }
}

/// An area, mm²: scaled by the square of the length's conversion.
pub(crate) fn scale_area(area: &mut f64, scaling: Scaling) {
    *area = scaling.apply(scaling.apply(*area));
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn messages_are_restated_in_inches() {
        let inch = Units::Inch.from_mm().unwrap();
        assert_eq!(
            inch.restate("tool radius 3.0000 mm exceeds the hole's 2.54 mm; feed 2540 mm/min (±25400 mm)"),
            "tool radius 0.11811 in exceeds the hole's 0.1000 in; feed 100.0 in/min (±1000.0000 in)"
        );
        assert_eq!(
            inch.restate("chord error 0.0005 mm, 645.16 mm², 16387.064 mm³"),
            "chord error 0.00001969 in, 1.0000 in², 1.0000000 in³"
        );
        assert_eq!(
            inch.restate("feed_per_tooth (mm/tooth) or feed (mm/min); a_p = 25.4mm."),
            "feed_per_tooth (in/tooth) or feed (in/min); a_p = 1.0000 in."
        );
        assert_eq!(inch.restate("-12.7 mm at s = 1e1 mm"), "-0.5000 in at s = 0.3937 in");
        // A length converted from inches, written out in full, reads as the inches it was.
        assert_eq!(inch.restate("from 0 mm to -152.39999999999998 mm"), "from 0.0000 in to -6.0000 in");
        // Not lengths in mm: counts, words of a program, other units, the name of the units.
        for kept in [
            "12 blocks",
            "X10 mm",
            "stiffness 3000 N/mm",
            "1 mm/N",
            "requests are read in mm only",
            "5 mmHg",
            "T1 (M3)",
        ] {
            assert_eq!(inch.restate(kept), kept);
        }
        assert_eq!(Units::Inch.into_mm().unwrap().restate("3 mm"), "3 mm");
    }

    proptest! {
        #[test]
        fn inch_to_mm_and_back_is_the_same_value(value in -1.0e6f64..1.0e6) {
            let mut scaled = value;
            scaled.scale(Units::Inch.into_mm().unwrap());
            prop_assert!((scaled - value * 25.4).abs() <= 1e-12 * scaled.abs().max(1.0));
            scaled.scale(Units::Inch.from_mm().unwrap());
            prop_assert!((scaled - value).abs() <= 1e-15 * value.abs().max(1e-300) * 4.0);
        }

        #[test]
        fn a_tool_round_trips(radius in 0.01f64..100.0, stickout in 1.0f64..500.0, feed in 1.0f64..1e5) {
            let mut tool: Tool = serde_json::from_value(serde_json::json!({
                "kind": "flat", "radius": radius, "flutes": 2, "stickout": stickout, "plunge_feed": feed,
                "helix_deg": 30.0
            })).unwrap();
            let original = tool.clone();
            tool.scale(Units::Inch.from_mm().unwrap());
            prop_assert!((tool.radius * 25.4 - radius).abs() <= 1e-12 * radius);
            prop_assert_eq!(tool.helix_deg, Some(30.0));
            tool.scale(Units::Inch.into_mm().unwrap());
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
            prop_assert!(close(tool.radius, original.radius));
            prop_assert!(close(tool.stickout.unwrap(), original.stickout.unwrap()));
            prop_assert!(close(tool.plunge_feed.unwrap(), original.plunge_feed.unwrap()));
        }
    }
}
