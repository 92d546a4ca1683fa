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

/// An area, mm²: scaled by the square of the length's conversion.
pub(crate) fn scale_area(area: &mut f64, scaling: Scaling) {
    *area = scaling.apply(scaling.apply(*area));
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

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
