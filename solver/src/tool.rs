//! The cutter: kind, radius and the optional data later capabilities need (docs/spec/api.md, Tools).

use std::fmt;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use crate::error::SolverError;

use crate::validate::{Measure, finite, positive};

/// The cutter's end shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum ToolKind {
    /// Ball end mill: `radius` is the ball radius.
    Ball,
    /// Flat (square) end mill.
    Flat,
    /// Bull-nose end mill: flat bottom with a `corner_radius`.
    Bull,
}

impl ToolKind {
    /// The name used in JSON and messages.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Ball => "ball",
            Self::Flat => "flat",
            Self::Bull => "bull",
        }
    }
}

/// A cutter as registered in the tool table or given inline in a request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// Tool number on the machine (1–9999). For a registered tool it is the table key (the
    /// path's number; the body may repeat it). For an inline tool it is the pocket the G-code
    /// calls (`T`/`H`); without it the program stops for a manual tool change.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "schema", schema(minimum = 1, maximum = 9999))]
    pub number: Option<u32>,
    /// End shape.
    pub kind: ToolKind,
    /// Cutter radius in mm (> 0); for `ball` the ball radius.
    pub radius: f64,
    /// Corner radius in mm, only for `bull` (required there, 0 < corner_radius ≤ radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner_radius: Option<f64>,
    /// Number of flutes (1–32).
    #[serde(default = "default_flutes")]
    #[cfg_attr(feature = "schema", schema(minimum = 1, maximum = 32))]
    pub flutes: u32,
    /// Free-text name shown in listings and G-code comments (at most 200 characters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Helix angle in degrees (0 ≤ helix < 90).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub helix_deg: Option<f64>,
    /// Length from the holder face to the tip in mm (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stickout: Option<f64>,
    /// Length of the cutting edge from the tip in mm (> 0): the deepest axial depth of cut the
    /// tool takes (an engagement path whose a_p exceeds it is refused).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flute_length: Option<f64>,
    /// Feed of straight moves down the tool axis (plunges), mm/min (> 0): programs never plunge
    /// faster. Default: the machine's `plunge_feed`, else half the cutting feed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Whether the end cuts at its centre, so the tool may plunge straight down into material.
    /// Default true; `false` (flat and bull tools with a centre hole or inserts)
    /// makes contour layers enter on a ramp. A ball always cuts at its centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_cutting: Option<bool>,
    /// Neck radius in mm of a lollipop or back-deburring cutter (0 < neck_radius < radius): the
    /// radius of the shank just above the cutting head. Without it the shank is taken to be as
    /// wide as the cutter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub neck_radius: Option<f64>,
    /// Length from the tip to the top of the neck in mm (> 0), only with `neck_radius`: how far
    /// the thin neck reaches before the shank. Default: the stickout (the neck reaches the
    /// holder). Only the verify simulation uses it (docs/spec/verify.md §2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub neck_length: Option<f64>,
    /// Shank radius in mm (> 0) between the cutting part (or the neck) and the holder. Default:
    /// the cutter radius. Only the verify simulation uses it (docs/spec/verify.md §2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shank_radius: Option<f64>,
    /// Diameter of the tool holder in mm (> 0), from the holder face (`stickout` above the tip)
    /// upward. Default: three shank diameters (a collet nut). Only the verify simulation uses it
    /// (docs/spec/verify.md §2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holder_diameter: Option<f64>,
    /// Length of the tool holder in mm (> 0) above the holder face. Default: 40 mm. Only the
    /// verify simulation uses it (docs/spec/verify.md §2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holder_length: Option<f64>,
    /// Shape-error table δ(θ) of the rotating cutting edge (docs/spec/predict.md §3.13): the
    /// outward deviation of the edge envelope from the nominal ball along its normal, in mm, at
    /// contact angles θ from 0° (tip) to 90° (equator), angles strictly increasing. Linear
    /// interpolation between rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_error: Option<Vec<ShapeErrorPoint>>,
    /// Tool-tip stiffness in X and Y (docs/spec/predict.md §3.8): static, modal or a measured
    /// frequency-response table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<Stiffness>,
}

/// One row of a tool's shape-error table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct ShapeErrorPoint {
    /// Contact angle θ in degrees: 0 at the tip, 90 at the equator.
    pub angle_deg: f64,
    /// δ(θ) in mm: positive where the rotating edge reaches outside the nominal ball (the tool
    /// cuts too deep there).
    pub error: f64,
}

/// One vibration mode of the tool tip: G(ω) = (1/k) / (1 − (ω/ωn)² + 2iζ ω/ωn).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from segment's mode in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = VibrationMode))]
#[serde(deny_unknown_fields)]
pub struct Mode {
    /// Modal stiffness k in N/mm (> 0).
    pub stiffness: f64,
    /// Natural frequency in Hz (> 0).
    pub frequency_hz: f64,
    /// Damping ratio ζ (0 < ζ < 1).
    pub damping_ratio: f64,
}

/// One row of a measured tool-tip compliance (receptance) table, e.g. from an impact test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct FrfPoint {
    /// Frequency in Hz (≥ 0, strictly increasing).
    pub frequency_hz: f64,
    /// Real part of the compliance, mm/N.
    pub real: f64,
    /// Imaginary part of the compliance, mm/N.
    pub imag: f64,
}

/// Tool-tip stiffness in the machine X and Y directions (no cross terms, no Z: the patent's model).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Stiffness {
    /// Static stiffness: deflection = force / k (the less accurate alternative).
    Static {
        /// k_x in N/mm.
        x: f64,
        /// k_y in N/mm.
        y: f64,
    },
    /// Sum of modes per direction (1–32 modes each).
    Modal {
        /// Modes in X.
        x: Vec<Mode>,
        /// Modes in Y.
        y: Vec<Mode>,
    },
    /// Measured compliance tables per direction (2–100 000 rows each), interpolated linearly in
    /// real and imaginary parts; zero above the last frequency.
    Frf {
        /// Table in X.
        x: Vec<FrfPoint>,
        /// Table in Y.
        y: Vec<FrfPoint>,
    },
}

/// Most rows of a shape-error table.
pub const MAX_SHAPE_ERROR_ROWS: usize = 1000;
/// Most modes per direction.
pub const MAX_MODES: usize = 32;
/// Most rows of a compliance table per direction.
pub const MAX_FRF_ROWS: usize = 100_000;

fn default_flutes() -> u32 {
    2
}

/// Longest accepted tool name.
pub const MAX_NAME_CHARS: usize = 200;

impl Tool {
    /// A tool of `kind` and `radius` with every optional datum left out.
    pub fn new(kind: ToolKind, radius: f64) -> Self {
        Self {
            number: None,
            kind,
            radius,
            corner_radius: None,
            flutes: default_flutes(),
            name: None,
            helix_deg: None,
            stickout: None,
            flute_length: None,
            plunge_feed: None,
            centre_cutting: None,
            neck_radius: None,
            neck_length: None,
            shank_radius: None,
            holder_diameter: None,
            holder_length: None,
            shape_error: None,
            stiffness: None,
        }
    }

    /// Whether the tool may plunge straight down into material.
    pub fn cuts_at_centre(&self) -> bool {
        self.centre_cutting.unwrap_or(true)
    }

    /// Checks every field; `prefix` is prepended to field names in errors (e.g. `tool.`).
    pub fn validate(&self, prefix: &str) -> Result<(), SolverError> {
        let field = |name: &str| format!("{prefix}{name}");
        if let Some(number) = self.number
            && !TOOL_NUMBERS.contains(&number)
        {
            return Err(SolverError::input(field("number"), format!("tool number must be 1 to 9999 (got {number})")));
        }
        positive(&field("radius"), self.radius, Measure::Length)?;
        match (self.kind, self.corner_radius) {
            (ToolKind::Bull, None) => {
                return Err(SolverError::input(field("corner_radius"), "a bull-nose tool needs corner_radius"));
            }
            (ToolKind::Bull, Some(corner)) => {
                positive(&field("corner_radius"), corner, Measure::Length)?;
                if corner > self.radius {
                    return Err(SolverError::input(
                        field("corner_radius"),
                        format!(
                            "corner_radius {} must not exceed radius {}",
                            Measure::Length.quote(corner),
                            Measure::Length.quote(self.radius)
                        ),
                    ));
                }
            }
            (kind, Some(_)) => {
                return Err(SolverError::input(
                    field("corner_radius"),
                    format!("corner_radius applies only to bull-nose tools, not {}", kind.as_str()),
                ));
            }
            (_, None) => {}
        }
        if !(1..=32).contains(&self.flutes) {
            return Err(SolverError::input(field("flutes"), format!("flutes must be 1 to 32 (got {})", self.flutes)));
        }
        if let Some(name) = &self.name {
            crate::validate::text(&field("name"), name, MAX_NAME_CHARS)?;
        }
        if let Some(helix) = self.helix_deg
            && !(0.0..90.0).contains(&finite(&field("helix_deg"), helix)?)
        {
            return Err(SolverError::input(field("helix_deg"), format!("helix_deg must be in [0, 90) (got {helix})")));
        }
        if let Some(stickout) = self.stickout {
            positive(&field("stickout"), stickout, Measure::Length)?;
        }
        if let Some(flute_length) = self.flute_length {
            positive(&field("flute_length"), flute_length, Measure::Length)?;
        }
        if let Some(plunge_feed) = self.plunge_feed {
            positive(&field("plunge_feed"), plunge_feed, Measure::Feed)?;
        }
        if self.kind == ToolKind::Ball && self.centre_cutting == Some(false) {
            return Err(SolverError::input(field("centre_cutting"), "a ball end mill always cuts at its centre"));
        }
        if let Some(neck) = self.neck_radius {
            positive(&field("neck_radius"), neck, Measure::Length)?;
            if neck >= self.radius {
                return Err(SolverError::input(
                    field("neck_radius"),
                    format!(
                        "neck_radius {} must be smaller than radius {}",
                        Measure::Length.quote(neck),
                        Measure::Length.quote(self.radius)
                    ),
                ));
            }
        }
        if let Some(length) = self.neck_length {
            positive(&field("neck_length"), length, Measure::Length)?;
            if self.neck_radius.is_none() {
                return Err(SolverError::input(field("neck_length"), "neck_length needs a neck_radius"));
            }
        }
        for (name, value) in [
            ("shank_radius", self.shank_radius),
            ("holder_diameter", self.holder_diameter),
            ("holder_length", self.holder_length),
        ] {
            if let Some(value) = value {
                positive(&field(name), value, Measure::Length)?;
            }
        }
        if let Some(table) = &self.shape_error {
            validate_shape_error(table, self.radius, &field("shape_error"))?;
        }
        if let Some(stiffness) = &self.stiffness {
            stiffness.validate(&field("stiffness"))?;
        }
        Ok(())
    }
}

fn validate_shape_error(table: &[ShapeErrorPoint], radius: f64, field: &str) -> Result<(), SolverError> {
    if table.is_empty() || table.len() > MAX_SHAPE_ERROR_ROWS {
        return Err(SolverError::input(
            field,
            format!("shape_error needs 1 to {MAX_SHAPE_ERROR_ROWS} rows (got {})", table.len()),
        ));
    }
    let mut previous = f64::NEG_INFINITY;
    for (index, row) in table.iter().enumerate() {
        let angle_field = format!("{field}[{index}].angle_deg");
        let angle = finite(&angle_field, row.angle_deg)?;
        if !(0.0..=90.0).contains(&angle) || angle <= previous {
            return Err(SolverError::input(
                angle_field,
                "shape_error angles must lie in [0, 90] degrees and increase strictly",
            ));
        }
        previous = angle;
        let error_field = format!("{field}[{index}].error");
        if finite(&error_field, row.error)?.abs() >= radius {
            return Err(SolverError::input(
                error_field,
                format!("a shape error of {} mm is not smaller than the tool radius", row.error),
            ));
        }
    }
    Ok(())
}

impl Stiffness {
    /// Checks every number; `field` is the stiffness's own path (e.g. `tool.stiffness`).
    pub fn validate(&self, field: &str) -> Result<(), SolverError> {
        match self {
            Self::Static { x, y } => {
                positive(&format!("{field}.x"), *x, Measure::Number)?;
                positive(&format!("{field}.y"), *y, Measure::Number)?;
            }
            Self::Modal { x, y } => {
                for (axis, modes) in [("x", x), ("y", y)] {
                    let axis_field = format!("{field}.{axis}");
                    if modes.is_empty() || modes.len() > MAX_MODES {
                        return Err(SolverError::input(
                            axis_field,
                            format!("give 1 to {MAX_MODES} modes per direction"),
                        ));
                    }
                    for (index, mode) in modes.iter().enumerate() {
                        let at = format!("{axis_field}[{index}]");
                        positive(&format!("{at}.stiffness"), mode.stiffness, Measure::Number)?;
                        positive(&format!("{at}.frequency_hz"), mode.frequency_hz, Measure::Number)?;
                        let damping = positive(&format!("{at}.damping_ratio"), mode.damping_ratio, Measure::Number)?;
                        if damping >= 1.0 {
                            return Err(SolverError::input(
                                format!("{at}.damping_ratio"),
                                "damping_ratio must be below 1 (an underdamped mode)",
                            ));
                        }
                    }
                }
            }
            Self::Frf { x, y } => {
                for (axis, rows) in [("x", x), ("y", y)] {
                    let axis_field = format!("{field}.{axis}");
                    if rows.len() < 2 || rows.len() > MAX_FRF_ROWS {
                        return Err(SolverError::input(
                            axis_field,
                            format!("give 2 to {MAX_FRF_ROWS} rows per direction"),
                        ));
                    }
                    let mut previous = f64::NEG_INFINITY;
                    for (index, row) in rows.iter().enumerate() {
                        let at = format!("{axis_field}[{index}]");
                        let frequency = finite(&format!("{at}.frequency_hz"), row.frequency_hz)?;
                        if frequency < 0.0 || frequency <= previous {
                            return Err(SolverError::input(
                                format!("{at}.frequency_hz"),
                                "frequencies must be at least 0 and increase strictly",
                            ));
                        }
                        previous = frequency;
                        finite(&format!("{at}.real"), row.real)?;
                        finite(&format!("{at}.imag"), row.imag)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Smallest and largest tool numbers (docs/spec/api.md, Tools).
pub const TOOL_NUMBERS: std::ops::RangeInclusive<u32> = 1..=9999;

/// How a solver request names its tool: a number in the tool table, or the tool itself.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(untagged)]
// A request holds one of these: boxing the inline tool would save nothing worth the indirection
// at every use.
#[allow(clippy::large_enum_variant)]
pub enum ToolRef {
    /// A registered tool number (1–9999).
    Number(u32),
    /// A tool given inline.
    Inline(Tool),
}

// Hand-written so that a bad inline tool reports its own field error instead of serde's
// "did not match any variant".
impl<'de> Deserialize<'de> for ToolRef {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ToolRefVisitor;

        impl<'de> Visitor<'de> for ToolRefVisitor {
            type Value = ToolRef;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a tool number (1-9999) or a tool object like {\"kind\": \"ball\", \"radius\": 3}")
            }

            fn visit_u64<E: de::Error>(self, value: u64) -> Result<ToolRef, E> {
                u32::try_from(value)
                    .ok()
                    .filter(|n| TOOL_NUMBERS.contains(n))
                    .map(ToolRef::Number)
                    .ok_or_else(|| E::custom(format!("tool number {value} is outside 1-9999")))
            }

            fn visit_i64<E: de::Error>(self, value: i64) -> Result<ToolRef, E> {
                u64::try_from(value)
                    .map_err(|_| E::custom(format!("tool number {value} is outside 1-9999")))
                    .and_then(|v| self.visit_u64(v))
            }

            fn visit_map<M: MapAccess<'de>>(self, map: M) -> Result<ToolRef, M::Error> {
                Tool::deserialize(de::value::MapAccessDeserializer::new(map)).map(ToolRef::Inline)
            }
        }

        deserializer.deserialize_any(ToolRefVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_field() {
        let mut tool = Tool::new(ToolKind::Ball, 3.0);
        assert!(tool.validate("tool.").is_ok());
        tool.radius = f64::NAN;
        assert_eq!(tool.validate("tool.").unwrap_err().field(), Some("tool.radius"));
        tool.radius = 3.0;
        tool.corner_radius = Some(1.0);
        assert_eq!(tool.validate("").unwrap_err().field(), Some("corner_radius"));
        let mut bull = Tool::new(ToolKind::Bull, 5.0);
        assert_eq!(bull.validate("").unwrap_err().field(), Some("corner_radius"));
        bull.corner_radius = Some(1.0);
        assert!(bull.validate("").is_ok());
        tool.corner_radius = None;
        tool.neck_radius = Some(3.0);
        assert_eq!(tool.validate("").unwrap_err().field(), Some("neck_radius"));
        tool.neck_radius = None;
        tool.flutes = 0;
        assert_eq!(tool.validate("").unwrap_err().field(), Some("flutes"));
    }

    #[test]
    fn prediction_data_is_validated() {
        let mut tool: Tool = serde_json::from_str(
            r#"{"kind": "ball", "radius": 5,
                "shape_error": [{"angle_deg": 0, "error": 0.005}, {"angle_deg": 90, "error": 0.015}],
                "stiffness": {"kind": "modal",
                              "x": [{"stiffness": 5000, "frequency_hz": 1370, "damping_ratio": 0.05}],
                              "y": [{"stiffness": 5000, "frequency_hz": 1370, "damping_ratio": 0.05}]}}"#,
        )
        .unwrap();
        assert!(tool.validate("tool.").is_ok());
        let round_trip: Tool = serde_json::from_str(&serde_json::to_string(&tool).unwrap()).unwrap();
        assert_eq!(round_trip, tool);
        tool.shape_error = Some(vec![
            ShapeErrorPoint { angle_deg: 30.0, error: 0.0 },
            ShapeErrorPoint { angle_deg: 30.0, error: 0.0 },
        ]);
        assert_eq!(tool.validate("tool.").unwrap_err().field(), Some("tool.shape_error[1].angle_deg"));
        tool.shape_error = Some(vec![ShapeErrorPoint { angle_deg: 95.0, error: 0.0 }]);
        assert!(tool.validate("tool.").is_err());
        tool.shape_error = None;
        tool.stiffness = Some(Stiffness::Static { x: 5000.0, y: -1.0 });
        assert_eq!(tool.validate("tool.").unwrap_err().field(), Some("tool.stiffness.y"));
        tool.stiffness = Some(Stiffness::Modal {
            x: vec![Mode { stiffness: 1.0, frequency_hz: 100.0, damping_ratio: 1.5 }],
            y: vec![],
        });
        assert_eq!(tool.validate("tool.").unwrap_err().field(), Some("tool.stiffness.x[0].damping_ratio"));
        tool.stiffness = Some(Stiffness::Frf {
            x: vec![
                FrfPoint { frequency_hz: 0.0, real: 1e-4, imag: 0.0 },
                FrfPoint { frequency_hz: 0.0, real: 1e-4, imag: 0.0 },
            ],
            y: vec![],
        });
        assert_eq!(tool.validate("tool.").unwrap_err().field(), Some("tool.stiffness.x[1].frequency_hz"));
        let plain: Tool = serde_json::from_str(r#"{"kind": "flat", "radius": 3}"#).unwrap();
        assert_eq!(plain.shape_error, None);
        assert_eq!(plain.stiffness, None);
    }

    #[test]
    fn tool_ref_reads_numbers_and_inline_tools() {
        let number: ToolRef = serde_json::from_str("7").unwrap();
        assert_eq!(number, ToolRef::Number(7));
        let inline: ToolRef = serde_json::from_str(r#"{"kind": "ball", "radius": 3}"#).unwrap();
        assert_eq!(inline, ToolRef::Inline(Tool::new(ToolKind::Ball, 3.0)));
        for bad in
            ["0", "10000", "-1", "2.5", r#""7""#, r#"{"kind": "ball"}"#, r#"{"kind": "ball", "radius": 3, "x": 1}"#]
        {
            assert!(serde_json::from_str::<ToolRef>(bad).is_err(), "{bad}");
        }
        let message = serde_json::from_str::<ToolRef>(r#"{"kind": "drill", "radius": 3}"#).unwrap_err().to_string();
        assert!(message.contains("unknown variant `drill`"), "{message}");
    }
}
