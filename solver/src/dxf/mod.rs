//! Reading a profile from a DXF drawing (docs/spec/dxf.md): the outer boundary and its islands
//! as closed polygons in mm, for contour's outline and segment's polyline curve.
//!
//! ASCII and binary DXF, R12 to 2018: LWPOLYLINE and POLYLINE (bulges as arcs), LINE, ARC,
//! CIRCLE, ELLIPSE and SPLINE (NURBS, control points) of the model space, in the XY plane (an
//! extrusion of −Z mirrors X, as the DXF object coordinate system says). Open entities are
//! joined end to end within the join tolerance; arcs, ellipses and splines become chords within
//! the chord tolerance. `$INSUNITS` gives the units; a drawing without them needs the request's.
//! The largest loop is the outer boundary, loops inside it are islands. Errors name the entity
//! (type, handle, layer) and, for an open chain, the gap, for a loop crossing itself, the point.

mod codes;
mod curves;

use serde::Serialize;

use crate::error::SolverError;
use codes::Group;
use curves::{Piece, bulge_points, flatten_arc, flatten_ellipse, flatten_spline};

/// Default join tolerance between the ends of two entities, mm.
pub const DEFAULT_JOIN_TOLERANCE: f64 = 0.01;
/// Default chord tolerance of arcs, ellipses and splines, mm.
pub const DEFAULT_CHORD_TOLERANCE: f64 = 0.001;
/// Most entities read from one drawing.
pub const MAX_ENTITIES: usize = 1_000_000;
/// Most points of all loops together.
pub const MAX_POINTS: usize = 2_000_000;

/// Length units of a drawing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
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
    fn from_insunits(code: i64) -> Option<Self> {
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

/// How to read a drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct DxfOptions {
    /// Units when the drawing has none (`$INSUNITS` 0 or missing, as every R12 file).
    pub units: Option<DrawingUnits>,
    /// Only entities of this layer (default all).
    pub layer: Option<String>,
    /// Largest gap between two ends joined, mm.
    pub join_tolerance: f64,
    /// Largest distance of a chord from its arc, ellipse or spline, mm.
    pub chord_tolerance: f64,
}

impl Default for DxfOptions {
    fn default() -> Self {
        Self {
            units: None,
            layer: None,
            join_tolerance: DEFAULT_JOIN_TOLERANCE,
            chord_tolerance: DEFAULT_CHORD_TOLERANCE,
        }
    }
}

/// The profile of a drawing.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Profile {
    /// The units the drawing was read in.
    pub units: DrawingUnits,
    /// The outer boundary, counter-clockwise, mm (the last point is not repeated).
    pub boundary: Vec<[f64; 2]>,
    /// The loops inside it, clockwise, mm.
    pub islands: Vec<Vec<[f64; 2]>>,
    /// Entities read (of the chosen layer).
    pub entities: usize,
    /// Every layer that has entities, sorted.
    pub layers: Vec<String>,
}

/// Reads the profile of a drawing; `field` names the file in errors.
///
/// # Errors
/// `E_INPUT` at `field` naming the entity (bad values, an open chain and its gap, a loop crossing
/// itself and where, a loop outside the boundary), at `units` when the drawing has no units
/// and none are given, at `layer` when the layer has no entities.
pub fn read(bytes: &[u8], field: &str, options: &DxfOptions) -> Result<Profile, SolverError> {
    crate::validate::positive("join_tolerance", options.join_tolerance)?;
    crate::validate::positive("chord_tolerance", options.chord_tolerance)?;
    let groups = codes::groups(bytes, field)?;
    let units = units_of(&groups, options.units)?;
    let scale = units.scale();
    let (entities, layers) = entities(&groups, field)?;
    let chosen: Vec<&Entity> =
        entities.iter().filter(|e| options.layer.as_deref().is_none_or(|layer| e.layer == layer)).collect();
    if chosen.is_empty() {
        return Err(match &options.layer {
            Some(layer) => SolverError::input(
                "layer",
                format!("layer \"{layer}\" has no entities; the drawing's layers: {}", layers.join(", ")),
            ),
            None => SolverError::input(field, "the drawing has no LINE, ARC, CIRCLE, ELLIPSE, SPLINE or polyline"),
        });
    }
    // The tolerances are in mm; the geometry is scaled to mm first.
    let mut closed: Vec<(Vec<[f64; 2]>, String)> = Vec::new();
    let mut open: Vec<Piece> = Vec::new();
    for entity in &chosen {
        let label = entity.label();
        match entity.geometry(scale, options.chord_tolerance, field)? {
            Geometry::Closed(points) => closed.push((points, label)),
            Geometry::Open(points) => open.push(Piece { points, label }),
        }
    }
    closed.extend(curves::join(open, options.join_tolerance, field)?);
    let total: usize = closed.iter().map(|(points, _)| points.len()).sum();
    if total > MAX_POINTS {
        return Err(SolverError::input(
            "chord_tolerance",
            format!("the loops have {total} points, over {MAX_POINTS}: a coarser chord_tolerance"),
        ));
    }
    for (points, label) in &closed {
        curves::check_simple(points, label, field)?;
    }
    let (boundary, islands) = curves::nest(closed, field)?;
    Ok(Profile { units, boundary, islands, entities: chosen.len(), layers })
}

/// The drawing's units from `$INSUNITS`, else `given`.
fn units_of(groups: &[Group], given: Option<DrawingUnits>) -> Result<DrawingUnits, SolverError> {
    let code = groups
        .iter()
        .position(|g| g.code == 9 && g.value == "$INSUNITS")
        .and_then(|at| groups.get(at + 1))
        .and_then(|g| g.value.parse::<i64>().ok())
        .unwrap_or(0);
    match (DrawingUnits::from_insunits(code), given) {
        (Some(units), Some(given)) if units != given => Err(SolverError::input(
            "units",
            format!("units {given:?} disagree with the drawing's $INSUNITS {code} ({units:?}): leave units out"),
        )),
        (Some(units), _) => Ok(units),
        (None, Some(given)) => Ok(given),
        (None, None) => Err(SolverError::input(
            "units",
            format!(
                "the drawing does not say its units ($INSUNITS {code}{}): give units (mm, cm, m, inch, foot or micron)",
                if code == 0 { ", unitless" } else { ", not taken" }
            ),
        )),
    }
}

/// One entity of the model space with its groups.
struct Entity {
    kind: String,
    handle: String,
    layer: String,
    groups: Vec<Group>,
    /// POLYLINE's VERTEX entities.
    vertices: Vec<Vec<Group>>,
}

enum Geometry {
    Closed(Vec<[f64; 2]>),
    Open(Vec<[f64; 2]>),
}

/// The entities of the ENTITIES section the reader takes, and every layer.
fn entities(groups: &[Group], field: &str) -> Result<(Vec<Entity>, Vec<String>), SolverError> {
    let Some(start) = groups.windows(2).position(|w| w[0].code == 2 && w[0].value == "ENTITIES" && w[1].code == 0)
    else {
        return Err(SolverError::input(field, "the drawing has no ENTITIES section"));
    };
    let mut out: Vec<Entity> = Vec::new();
    let mut layers: Vec<String> = Vec::new();
    let mut at = start + 1;
    while at < groups.len() {
        let kind = &groups[at].value;
        if kind == "ENDSEC" || kind == "EOF" {
            break;
        }
        let end = groups[at + 1..].iter().position(|g| g.code == 0).map_or(groups.len(), |p| at + 1 + p);
        let body = groups[at + 1..end].to_vec();
        at = end;
        let value = |code: i32| body.iter().find(|g| g.code == code).map(|g| g.value.clone());
        let layer = value(8).unwrap_or_else(|| "0".to_owned());
        match kind.as_str() {
            "VERTEX" => {
                if let Some(polyline) = out.last_mut().filter(|e| e.kind == "POLYLINE") {
                    polyline.vertices.push(body);
                }
                continue;
            }
            "SEQEND" => continue,
            "LINE" | "ARC" | "CIRCLE" | "ELLIPSE" | "SPLINE" | "LWPOLYLINE" | "POLYLINE" => {}
            // Text, dimensions, hatches, blocks: not the profile.
            _ => continue,
        }
        // Paper space (67 = 1) is the sheet, not the part.
        if value(67).as_deref() == Some("1") {
            continue;
        }
        if !layers.contains(&layer) {
            layers.push(layer.clone());
        }
        if out.len() >= MAX_ENTITIES {
            return Err(SolverError::input(field, format!("the drawing has more than {MAX_ENTITIES} entities")));
        }
        out.push(Entity {
            kind: kind.clone(),
            handle: value(5).unwrap_or_default(),
            layer,
            groups: body,
            vertices: Vec::new(),
        });
    }
    layers.sort();
    Ok((out, layers))
}

impl Entity {
    fn label(&self) -> String {
        let handle = if self.handle.is_empty() { String::new() } else { format!(" {}", self.handle) };
        format!("{}{handle} on layer {}", self.kind, self.layer)
    }

    fn numbers(&self, code: i32) -> impl Iterator<Item = &str> {
        self.groups.iter().filter(move |g| g.code == code).map(|g| g.value.as_str())
    }

    fn number(&self, code: i32, default: Option<f64>, field: &str) -> Result<f64, SolverError> {
        match self.numbers(code).next() {
            Some(text) => parse(text, code, &self.label(), field),
            None => {
                default.ok_or_else(|| SolverError::input(field, format!("{} has no group code {code}", self.label())))
            }
        }
    }

    /// −1 when the extrusion points down (the entity's X is mirrored), else 1.
    fn mirror(&self, field: &str) -> Result<f64, SolverError> {
        Ok(if self.number(230, Some(1.0), field)? < 0.0 { -1.0 } else { 1.0 })
    }

    fn geometry(&self, scale: f64, tolerance: f64, field: &str) -> Result<Geometry, SolverError> {
        let label = self.label();
        let mirror = self.mirror(field)?;
        let point = |x: f64, y: f64| [mirror * x * scale, y * scale];
        match self.kind.as_str() {
            "LINE" => {
                let a = point(self.number(10, None, field)?, self.number(20, None, field)?);
                let b = point(self.number(11, None, field)?, self.number(21, None, field)?);
                Ok(Geometry::Open(vec![a, b]))
            }
            "CIRCLE" | "ARC" => {
                let centre = point(self.number(10, None, field)?, self.number(20, None, field)?);
                let radius = self.number(40, None, field)? * scale;
                if radius.is_nan() || radius <= 0.0 {
                    return Err(SolverError::input(field, format!("{label}: radius {radius} is not positive")));
                }
                if self.kind == "CIRCLE" {
                    let mut points = flatten_arc(centre, radius, 0.0, std::f64::consts::TAU, tolerance);
                    points.pop();
                    return Ok(Geometry::Closed(points));
                }
                let (mut start, mut end) =
                    (self.number(50, None, field)?.to_radians(), self.number(51, None, field)?.to_radians());
                if mirror < 0.0 {
                    (start, end) = (std::f64::consts::PI - start, std::f64::consts::PI - end);
                }
                let mut sweep = (end - start).rem_euclid(std::f64::consts::TAU);
                if sweep == 0.0 {
                    sweep = std::f64::consts::TAU;
                }
                Ok(Geometry::Open(flatten_arc(centre, radius, start, mirror * sweep, tolerance)))
            }
            "ELLIPSE" => {
                let centre = point(self.number(10, None, field)?, self.number(20, None, field)?);
                let major = [mirror * self.number(11, None, field)? * scale, self.number(21, None, field)? * scale];
                let ratio = self.number(40, None, field)?;
                let start = self.number(41, Some(0.0), field)?;
                let end = self.number(42, Some(std::f64::consts::TAU), field)?;
                if ratio.is_nan() || ratio <= 0.0 || ratio > 1.0 || major[0].hypot(major[1]) == 0.0 {
                    return Err(SolverError::input(
                        field,
                        format!("{label}: ratio {ratio} or its major axis is not valid"),
                    ));
                }
                let mut sweep = (end - start).rem_euclid(std::f64::consts::TAU);
                let full = sweep < 1e-12 || (sweep - std::f64::consts::TAU).abs() < 1e-12;
                if full {
                    sweep = std::f64::consts::TAU;
                }
                let mut points = flatten_ellipse(centre, major, ratio * mirror, start, sweep, tolerance);
                if full {
                    points.pop();
                    return Ok(Geometry::Closed(points));
                }
                Ok(Geometry::Open(points))
            }
            "SPLINE" => self.spline(scale, tolerance, field),
            "LWPOLYLINE" => {
                let flags = self.number(70, Some(0.0), field)? as i64;
                let mut vertices: Vec<([f64; 2], f64)> = Vec::new();
                for group in &self.groups {
                    match group.code {
                        10 => vertices.push(([parse(&group.value, 10, &label, field)?, 0.0], 0.0)),
                        20 => {
                            if let Some(last) = vertices.last_mut() {
                                last.0[1] = parse(&group.value, 20, &label, field)?;
                            }
                        }
                        42 => {
                            if let Some(last) = vertices.last_mut() {
                                last.1 = parse(&group.value, 42, &label, field)?;
                            }
                        }
                        _ => {}
                    }
                }
                let vertices = vertices.into_iter().map(|(p, b)| (point(p[0], p[1]), mirror * b)).collect();
                polyline(vertices, flags & 1 == 1, tolerance, &label, field)
            }
            "POLYLINE" => {
                let flags = self.number(70, Some(0.0), field)? as i64;
                if flags & (16 | 64) != 0 {
                    return Err(SolverError::input(field, format!("{label} is a mesh, not a profile")));
                }
                let mut vertices = Vec::new();
                for vertex in &self.vertices {
                    let get = |code: i32, default: Option<f64>| -> Result<f64, SolverError> {
                        match vertex.iter().find(|g| g.code == code) {
                            Some(g) => parse(&g.value, code, &label, field),
                            None => default.ok_or_else(|| {
                                SolverError::input(field, format!("{label}: a VERTEX has no group code {code}"))
                            }),
                        }
                    };
                    vertices.push((point(get(10, None)?, get(20, None)?), mirror * get(42, Some(0.0))?));
                }
                polyline(vertices, flags & 1 == 1, tolerance, &label, field)
            }
            _ => Err(SolverError::input(field, format!("{label} is not read"))),
        }
    }

    fn spline(&self, scale: f64, tolerance: f64, field: &str) -> Result<Geometry, SolverError> {
        let label = self.label();
        let mirror = self.mirror(field)?;
        let degree = self.number(71, None, field)?;
        let knots: Vec<f64> = self.numbers(40).map(|t| parse(t, 40, &label, field)).collect::<Result<_, _>>()?;
        let weights: Vec<f64> = self.numbers(41).map(|t| parse(t, 41, &label, field)).collect::<Result<_, _>>()?;
        let xs: Vec<f64> = self.numbers(10).map(|t| parse(t, 10, &label, field)).collect::<Result<_, _>>()?;
        let ys: Vec<f64> = self.numbers(20).map(|t| parse(t, 20, &label, field)).collect::<Result<_, _>>()?;
        if xs.is_empty() {
            return Err(SolverError::input(field, format!("{label} has fit points only: save it with control points")));
        }
        let control: Vec<[f64; 2]> = xs.iter().zip(&ys).map(|(x, y)| [mirror * x * scale, y * scale]).collect();
        let degree = degree as usize;
        if !(1..=11).contains(&degree) || knots.len() != control.len() + degree + 1 || xs.len() != ys.len() {
            return Err(SolverError::input(
                field,
                format!(
                    "{label}: degree {degree}, {} knots and {} control points do not fit",
                    knots.len(),
                    control.len()
                ),
            ));
        }
        let weights = if weights.len() == control.len() { weights } else { vec![1.0; control.len()] };
        if weights.iter().any(|w| w.is_nan() || *w <= 0.0) || knots.windows(2).any(|k| k[1] < k[0]) {
            return Err(SolverError::input(field, format!("{label}: a weight is not positive or the knots fall")));
        }
        let mut points = flatten_spline(degree, &control, &knots, &weights, tolerance);
        let closed = points.len() > 2 && distance(points[0], points[points.len() - 1]) <= 1e-9;
        if closed {
            points.pop();
            return Ok(Geometry::Closed(points));
        }
        Ok(Geometry::Open(points))
    }
}

fn parse(text: &str, code: i32, label: &str, field: &str) -> Result<f64, SolverError> {
    match text.trim().parse::<f64>() {
        Ok(value) if value.is_finite() && value.abs() <= crate::validate::MAX_COORDINATE * 1000.0 => Ok(value),
        _ => Err(SolverError::input(field, format!("{label}: group code {code} value \"{text}\" is not a number"))),
    }
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// A polyline's vertices with their bulges, closed or open, as points.
fn polyline(
    vertices: Vec<([f64; 2], f64)>,
    closed: bool,
    tolerance: f64,
    label: &str,
    field: &str,
) -> Result<Geometry, SolverError> {
    if vertices.len() < 2 {
        return Err(SolverError::input(field, format!("{label} has fewer than two vertices")));
    }
    let mut points = vec![vertices[0].0];
    let count = if closed { vertices.len() } else { vertices.len() - 1 };
    for index in 0..count {
        let (from, bulge) = vertices[index];
        let to = vertices[(index + 1) % vertices.len()].0;
        points.extend(bulge_points(from, to, bulge, tolerance));
    }
    if closed {
        points.pop();
        Ok(Geometry::Closed(points))
    } else {
        Ok(Geometry::Open(points))
    }
}

#[cfg(test)]
mod tests;
