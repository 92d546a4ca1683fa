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

use crate::validate::Measure;
use serde::Serialize;

use std::collections::HashMap;

use crate::error::SolverError;
use crate::segment::Curve;
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

pub use crate::units::DrawingUnits;

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

/// A DXF file uploaded with a contour or segment request as the source of its outline or curve
/// (docs/spec/dxf.md §5): how to read it, as the query of `POST /api/v1/dxf` says.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Drawing {
    /// Units of a drawing that does not say them (`$INSUNITS` 0 or missing, as every R12 file);
    /// refused when the drawing says others.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<DrawingUnits>,
    /// Only the entities of this layer (default all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<String>,
    /// The loop taken: island n (from 1, in the order `POST /api/v1/dxf` lists them, clockwise)
    /// instead of the outer boundary (counter-clockwise, the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub island: Option<usize>,
    /// Largest gap between two entity ends joined, in the request's units (default 0.01 mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub join_tolerance: Option<f64>,
    /// Largest distance of a chord from its arc, bulge, ellipse or spline, in the request's units
    /// (default 0.001 mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chord_tolerance: Option<f64>,
}

impl Drawing {
    /// The reader's options.
    pub fn options(&self) -> DxfOptions {
        DxfOptions {
            units: self.units,
            layer: self.layer.clone(),
            join_tolerance: self.join_tolerance.unwrap_or(DEFAULT_JOIN_TOLERANCE),
            chord_tolerance: self.chord_tolerance.unwrap_or(DEFAULT_CHORD_TOLERANCE),
        }
    }

    /// The drawing's profile; `at` is where the source sits in the request (`drawing`,
    /// `curve`): errors about the file name `drawing` (the form part), about an option `at.option`.
    fn profile(&self, upload: Option<&[u8]>, at: &str) -> Result<Profile, SolverError> {
        let Some(bytes) = upload else {
            return Err(SolverError::input(
                at,
                "a drawing needs its DXF file uploaded with the request: send multipart/form-data with the JSON in \
                 part `request` and the file in part `drawing` (a job file cannot carry one: read it with POST \
                 /api/v1/dxf and send the points)",
            ));
        };
        read(bytes, "drawing", &self.options()).map_err(|error| match error.field() {
            Some(option @ ("units" | "layer" | "join_tolerance" | "chord_tolerance")) => {
                let field = format!("{at}.{option}");
                error.at(field)
            }
            _ => error,
        })
    }

    /// The polygon contour cuts, counter-clockwise as contour takes every polygon: the outer
    /// boundary, or the island chosen (turned).
    ///
    /// # Errors
    /// As [`read`], and at `at.island` for an island the drawing does not have.
    pub fn outline(&self, upload: Option<&[u8]>, at: &str) -> Result<Vec<[f64; 2]>, SolverError> {
        let profile = self.profile(upload, at)?;
        let mut polygon = self.chosen_loop(profile, at)?;
        if self.island.is_some() {
            polygon.reverse();
        }
        Ok(polygon)
    }

    fn chosen_loop(&self, profile: Profile, at: &str) -> Result<Vec<[f64; 2]>, SolverError> {
        if profile.boundary.is_empty() {
            return Err(SolverError::input("drawing", "the drawing is one open SPLINE: it has no closed loop"));
        }
        match self.island {
            None => Ok(profile.boundary),
            Some(n) => {
                let count = profile.islands.len();
                profile.islands.into_iter().nth(n.wrapping_sub(1)).ok_or_else(|| {
                    let has = if count == 0 { "no islands".to_owned() } else { format!("islands 1 to {count}") };
                    SolverError::input(format!("{at}.island"), format!("the drawing has {has}: no island {n}"))
                })
            }
        }
    }

    /// The curve segment cuts: a drawing of one SPLINE is that NURBS exactly (a `bspline` curve),
    /// else the loop chosen as a closed `polyline`.
    ///
    /// # Errors
    /// As [`Drawing::outline`].
    pub fn curve(&self, upload: Option<&[u8]>, at: &str, corner_angle_deg: Option<f64>) -> Result<Curve, SolverError> {
        let mut profile = self.profile(upload, at)?;
        if self.island.is_none()
            && let Some(Curve::Bspline { degree, control_points, knots, weights, .. }) = profile.curve.take()
        {
            return Ok(Curve::Bspline { degree, control_points, knots, weights, corner_angle_deg });
        }
        let mut points: Vec<Vec<f64>> = self.chosen_loop(profile, at)?.iter().map(|p| p.to_vec()).collect();
        points.push(points[0].clone());
        Ok(Curve::Polyline { points, corner_angle_deg })
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
    /// When the entities read are one SPLINE: the curve exactly, as segment's `bspline` curve
    /// (mm, clamped knots). An open SPLINE has no loops: `boundary` and `islands` are empty.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curve: Option<Curve>,
}

/// Reads the profile of a drawing; `field` names the file in errors.
///
/// # Errors
/// `E_INPUT` at `field` naming the entity (bad values, an open chain and its gap, a loop crossing
/// itself and where, a loop outside the boundary), at `units` when the drawing has no units
/// and none are given, at `layer` when the layer has no entities.
pub fn read(bytes: &[u8], field: &str, options: &DxfOptions) -> Result<Profile, SolverError> {
    crate::validate::positive("join_tolerance", options.join_tolerance, Measure::Length)?;
    crate::validate::positive("chord_tolerance", options.chord_tolerance, Measure::Length)?;
    let groups = codes::groups(bytes, field)?;
    let units = units_of(&groups, options.units)?;
    let scale = units.scale();
    let blocks = blocks(&groups, field)?;
    let start = groups
        .windows(2)
        .position(|w| w[0].code == 2 && w[0].value == "ENTITIES" && w[1].code == 0)
        .map_or(groups.len(), |at| at + 1);
    let (raws, _) = raw_entities(&groups, start);
    let (entities, layers) = entities(&groups, &raws, &blocks, scale, field)?;
    let chosen: Vec<&Entity<'_>> =
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
    let curve = match chosen.as_slice() {
        [only] if only.raw.kind == "SPLINE" => Some(spline_curve(only, scale, field)?),
        _ => None,
    };
    // The tolerances are in mm; the geometry is scaled to mm first.
    let mut closed: Vec<(Vec<[f64; 2]>, String)> = Vec::new();
    let mut open: Vec<Piece> = Vec::new();
    for entity in &chosen {
        let label = entity.label();
        match entity.placed(scale, options.chord_tolerance, field)? {
            Geometry::Closed(points) => closed.push((points, label)),
            Geometry::Open(points) => open.push(Piece { points, label }),
        }
    }
    // One open SPLINE is a curve for segment, not a profile: it has no loops.
    if curve.is_some() && closed.is_empty() {
        return Ok(Profile { units, boundary: Vec::new(), islands: Vec::new(), curve, entities: 1, layers });
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
    Ok(Profile { units, boundary, islands, curve, entities: chosen.len(), layers })
}

/// A SPLINE as segment's exact curve: its NURBS placed in the drawing (an affine map moves the
/// control points and leaves knots and weights), clamped when its knots are not.
fn spline_curve(entity: &Entity<'_>, scale: f64, field: &str) -> Result<Curve, SolverError> {
    let label = entity.label();
    let Spline { degree, control, knots, weights } = entity.spline_data(scale, field)?;
    if degree > crate::segment::MAX_DEGREE {
        return Err(SolverError::input(
            field,
            format!("{label}: degree {degree}, over the {} segment's curves take", crate::segment::MAX_DEGREE),
        ));
    }
    let control: Vec<[f64; 2]> = control.into_iter().map(|p| entity.transform.apply(p)).collect();
    let (control, knots, weights) = curves::clamped(degree, control, knots, weights);
    let plain = weights.iter().all(|w| *w == weights[0]);
    Ok(Curve::Bspline {
        degree,
        control_points: control.iter().map(|p| p.to_vec()).collect(),
        knots: Some(knots),
        weights: (!plain).then_some(weights),
        corner_angle_deg: None,
    })
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

/// An entity as written in the ENTITIES section or a block, with its groups.
struct Raw {
    kind: String,
    handle: String,
    layer: String,
    groups: Vec<Group>,
    /// POLYLINE's VERTEX entities.
    vertices: Vec<Vec<Group>>,
}

/// A block of the BLOCKS section: its base point (drawing units) and its entities.
struct Block {
    base: [f64; 2],
    entities: Vec<Raw>,
}

/// An entity of the model space: written there, or in a block an INSERT places, with the
/// placement from the block's coordinates to the drawing's (mm to mm).
struct Entity<'a> {
    raw: &'a Raw,
    /// The layer it is drawn on: a block's entities on layer 0 take their INSERT's layer.
    layer: String,
    transform: Affine,
    /// The block it came from, for messages.
    block: Option<&'a str>,
}

enum Geometry {
    Closed(Vec<[f64; 2]>),
    Open(Vec<[f64; 2]>),
}

/// Deepest nesting of blocks expanded (a block that inserts itself is refused at this depth).
pub const MAX_BLOCK_DEPTH: usize = 8;

/// The value of the first group `code` of `body`.
fn value_of(body: &[Group], code: i32) -> Option<&str> {
    body.iter().find(|g| g.code == code).map(|g| g.value.as_str())
}

/// The entities from `groups[at]` (a code 0 group) up to the end of their section or block
/// (ENDSEC, ENDBLK or EOF), and where that end is. Only what the profile can use is kept: the
/// drawn kinds and INSERT; paper space (67 = 1) is the sheet, not the part.
fn raw_entities(groups: &[Group], mut at: usize) -> (Vec<Raw>, usize) {
    let mut out: Vec<Raw> = Vec::new();
    while at < groups.len() {
        let kind = &groups[at].value;
        if kind == "ENDSEC" || kind == "EOF" || kind == "ENDBLK" {
            break;
        }
        let end = groups[at + 1..].iter().position(|g| g.code == 0).map_or(groups.len(), |p| at + 1 + p);
        let body = &groups[at + 1..end];
        let kind = kind.clone();
        at = end;
        match kind.as_str() {
            "VERTEX" => {
                if let Some(polyline) = out.last_mut().filter(|e| e.kind == "POLYLINE") {
                    polyline.vertices.push(body.to_vec());
                }
                continue;
            }
            "SEQEND" => continue,
            "LINE" | "ARC" | "CIRCLE" | "ELLIPSE" | "SPLINE" | "LWPOLYLINE" | "POLYLINE" | "INSERT" => {}
            // Text, dimensions, hatches: not the profile.
            _ => continue,
        }
        if value_of(body, 67) == Some("1") {
            continue;
        }
        out.push(Raw {
            kind,
            handle: value_of(body, 5).unwrap_or_default().to_owned(),
            layer: value_of(body, 8).unwrap_or("0").to_owned(),
            groups: body.to_vec(),
            vertices: Vec::new(),
        });
    }
    (out, at)
}

/// The blocks of the BLOCKS section by name.
fn blocks(groups: &[Group], field: &str) -> Result<HashMap<String, Block>, SolverError> {
    let mut out = HashMap::new();
    let Some(start) = groups.windows(2).position(|w| w[0].code == 2 && w[0].value == "BLOCKS" && w[1].code == 0) else {
        return Ok(out);
    };
    let mut at = start + 1;
    while at < groups.len() && groups[at].value != "ENDSEC" && groups[at].value != "EOF" {
        let end = groups[at + 1..].iter().position(|g| g.code == 0).map_or(groups.len(), |p| at + 1 + p);
        if groups[at].value != "BLOCK" {
            at = end;
            continue;
        }
        let body = &groups[at + 1..end];
        let name = value_of(body, 2).unwrap_or_default().to_owned();
        let label = format!("block {name}");
        let number = |code: i32| value_of(body, code).map_or(Ok(0.0), |text| parse(text, code, &label, field));
        let base = [number(10)?, number(20)?];
        let (entities, stop) = raw_entities(groups, end);
        // Past ENDBLK and its groups.
        at = groups[stop + 1..].iter().position(|g| g.code == 0).map_or(groups.len(), |p| stop + 1 + p);
        out.insert(name, Block { base, entities });
    }
    Ok(out)
}

/// The entities of the model space, blocks expanded, and every layer.
fn entities<'a>(
    groups: &[Group],
    raws: &'a [Raw],
    blocks: &'a HashMap<String, Block>,
    scale: f64,
    field: &str,
) -> Result<(Vec<Entity<'a>>, Vec<String>), SolverError> {
    if !groups.windows(2).any(|w| w[0].code == 2 && w[0].value == "ENTITIES" && w[1].code == 0) {
        return Err(SolverError::input(field, "the drawing has no ENTITIES section"));
    }
    let mut out = Vec::new();
    let placement = Placement { transform: Affine::IDENTITY, layer: None, block: None, depth: 0 };
    expand(raws, blocks, &placement, scale, field, &mut out)?;
    let mut layers: Vec<String> = Vec::new();
    for entity in &out {
        if !layers.contains(&entity.layer) {
            layers.push(entity.layer.clone());
        }
    }
    layers.sort();
    Ok((out, layers))
}

/// Where a list of entities is placed: the transform to the drawing, the INSERT's layer their
/// layer-0 entities take, the block's name and how deep it is nested.
struct Placement<'a> {
    transform: Affine,
    layer: Option<String>,
    block: Option<&'a str>,
    depth: usize,
}

fn expand<'a>(
    raws: &'a [Raw],
    blocks: &'a HashMap<String, Block>,
    placement: &Placement<'a>,
    scale: f64,
    field: &str,
    out: &mut Vec<Entity<'a>>,
) -> Result<(), SolverError> {
    for raw in raws {
        let layer = match &placement.layer {
            Some(inherited) if raw.layer == "0" => inherited.clone(),
            _ => raw.layer.clone(),
        };
        if raw.kind != "INSERT" {
            if out.len() >= MAX_ENTITIES {
                return Err(SolverError::input(field, format!("the drawing has more than {MAX_ENTITIES} entities")));
            }
            out.push(Entity { raw, layer, transform: placement.transform, block: placement.block });
            continue;
        }
        let entity = Entity { raw, layer: layer.clone(), transform: placement.transform, block: placement.block };
        let label = entity.label();
        let name = value_of(&raw.groups, 2).unwrap_or_default();
        let Some((name, block)) = blocks.get_key_value(name) else {
            return Err(SolverError::input(
                field,
                format!("{label} places block \"{name}\", which the drawing does not define"),
            ));
        };
        if placement.depth >= MAX_BLOCK_DEPTH {
            return Err(SolverError::input(
                field,
                format!("{label} nests blocks more than {MAX_BLOCK_DEPTH} deep (a block that places itself?)"),
            ));
        }
        let number = |code: i32, default: f64| entity.number(code, Some(default), field);
        let mirror = entity.mirror(field)?;
        let at = [number(10, 0.0)? * scale, number(20, 0.0)? * scale];
        let (sx, sy) = (number(41, 1.0)?, number(42, 1.0)?);
        let angle = number(50, 0.0)?.to_radians();
        let (columns, rows) = (number(70, 1.0)?.max(1.0) as usize, number(71, 1.0)?.max(1.0) as usize);
        let (column_step, row_step) = (number(44, 0.0)? * scale, number(45, 0.0)? * scale);
        if sx == 0.0 || sy == 0.0 || columns.saturating_mul(rows) > MAX_ENTITIES {
            return Err(SolverError::input(field, format!("{label}: a scale of 0 or more than {MAX_ENTITIES} copies")));
        }
        let base = [block.base[0] * scale, block.base[1] * scale];
        let (cos, sin) = (angle.cos(), angle.sin());
        for row in 0..rows {
            for column in 0..columns {
                // Block point q: at + R(angle)·(S·(q − base) + the copy's offset), then the
                // INSERT's object coordinates to the drawing's (X mirrored under a −Z extrusion).
                let offset = [column as f64 * column_step, row as f64 * row_step];
                let local = Affine([[sx * cos, -sy * sin, 0.0], [sx * sin, sy * cos, 0.0]]).then_translate([
                    at[0] + cos * (offset[0] - sx * base[0]) - sin * (offset[1] - sy * base[1]),
                    at[1] + sin * (offset[0] - sx * base[0]) + cos * (offset[1] - sy * base[1]),
                ]);
                let placed = Affine([[mirror, 0.0, 0.0], [0.0, 1.0, 0.0]]).after(&local);
                let inner = Placement {
                    transform: placement.transform.after(&placed),
                    layer: Some(layer.clone()),
                    block: Some(name.as_str()),
                    depth: placement.depth + 1,
                };
                expand(&block.entities, blocks, &inner, scale, field, out)?;
            }
        }
    }
    Ok(())
}

/// A plane affine map `[[a, b, tx], [c, d, ty]]`: p ↦ (a·x + b·y + tx, c·x + d·y + ty).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Affine([[f64; 3]; 2]);

impl Affine {
    const IDENTITY: Self = Self([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);

    fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let m = &self.0;
        [m[0][0] * p[0] + m[0][1] * p[1] + m[0][2], m[1][0] * p[0] + m[1][1] * p[1] + m[1][2]]
    }

    fn then_translate(mut self, by: [f64; 2]) -> Self {
        self.0[0][2] += by[0];
        self.0[1][2] += by[1];
        self
    }

    /// `self` after `inner`: p ↦ self(inner(p)).
    fn after(&self, inner: &Self) -> Self {
        let (m, n) = (&self.0, &inner.0);
        let row = |r: usize| {
            [
                m[r][0] * n[0][0] + m[r][1] * n[1][0],
                m[r][0] * n[0][1] + m[r][1] * n[1][1],
                m[r][0] * n[0][2] + m[r][1] * n[1][2] + m[r][2],
            ]
        };
        Self([row(0), row(1)])
    }

    /// The largest factor by which the map stretches a length (its largest singular value).
    fn stretch(&self) -> f64 {
        let m = &self.0;
        let (a, b, c, d) = (m[0][0], m[0][1], m[1][0], m[1][1]);
        let t = a * a + b * b + c * c + d * d;
        let det = a * d - b * c;
        ((t + (t * t - 4.0 * det * det).max(0.0).sqrt()) / 2.0).sqrt()
    }

    fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }
}

impl Entity<'_> {
    fn label(&self) -> String {
        let handle = if self.raw.handle.is_empty() { String::new() } else { format!(" {}", self.raw.handle) };
        let block = self.block.map_or(String::new(), |name| format!(" in block {name}"));
        format!("{}{handle} on layer {}{block}", self.raw.kind, self.layer)
    }

    fn numbers(&self, code: i32) -> impl Iterator<Item = &str> {
        self.raw.groups.iter().filter(move |g| g.code == code).map(|g| g.value.as_str())
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
        match self.raw.kind.as_str() {
            "LINE" => {
                let a = point(self.number(10, None, field)?, self.number(20, None, field)?);
                let b = point(self.number(11, None, field)?, self.number(21, None, field)?);
                Ok(Geometry::Open(vec![a, b]))
            }
            "CIRCLE" | "ARC" => {
                let centre = point(self.number(10, None, field)?, self.number(20, None, field)?);
                let radius = self.number(40, None, field)? * scale;
                if radius.is_nan() || radius <= 0.0 {
                    return Err(SolverError::input(
                        field,
                        format!("{label}: radius {} is not positive", Measure::Length.quote(radius)),
                    ));
                }
                if self.raw.kind == "CIRCLE" {
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
                for group in &self.raw.groups {
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
                for vertex in &self.raw.vertices {
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

    /// The SPLINE's NURBS in the entity's own mm (before its placement).
    fn spline_data(&self, scale: f64, field: &str) -> Result<Spline, SolverError> {
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
        if knots[control.len()] <= knots[degree] {
            return Err(SolverError::input(field, format!("{label}: its knots span no length")));
        }
        Ok(Spline { degree, control, knots, weights })
    }

    fn spline(&self, scale: f64, tolerance: f64, field: &str) -> Result<Geometry, SolverError> {
        let Spline { degree, control, knots, weights } = self.spline_data(scale, field)?;
        let mut points = flatten_spline(degree, &control, &knots, &weights, tolerance);
        let closed = points.len() > 2 && distance(points[0], points[points.len() - 1]) <= 1e-9;
        if closed {
            points.pop();
            return Ok(Geometry::Closed(points));
        }
        Ok(Geometry::Open(points))
    }

    /// The entity's points in the drawing, mm: its geometry within `tolerance` placed by its
    /// block's transform.
    fn placed(&self, scale: f64, tolerance: f64, field: &str) -> Result<Geometry, SolverError> {
        if self.transform.is_identity() {
            return self.geometry(scale, tolerance, field);
        }
        let stretch = self.transform.stretch();
        let place = |points: Vec<[f64; 2]>| points.into_iter().map(|p| self.transform.apply(p)).collect();
        Ok(match self.geometry(scale, tolerance / stretch, field)? {
            Geometry::Closed(points) => Geometry::Closed(place(points)),
            Geometry::Open(points) => Geometry::Open(place(points)),
        })
    }
}

/// A SPLINE's NURBS: degree, control points (mm), knots and weights.
struct Spline {
    degree: usize,
    control: Vec<[f64; 2]>,
    knots: Vec<f64>,
    weights: Vec<f64>,
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

/// A DXF drawing's tolerances (its geometry is in the drawing's own units, `$INSUNITS` or `units`).
impl crate::units::Scale for Drawing {
    fn scale(&mut self, scaling: crate::units::Scaling) {
        let Self { units: _, layer: _, island: _, join_tolerance, chord_tolerance } = self;
        join_tolerance.scale(scaling);
        chord_tolerance.scale(scaling);
    }
}

/// Segment's `drawing` curve read from its file: here, so the reader's types stay below
/// segment's.
impl Curve {
    /// A `drawing` curve read from `upload`, the DXF file sent with the request; any other curve
    /// as it is (and then no file may be sent).
    ///
    /// # Errors
    /// `E_INPUT`: a drawing without its file, a file without a drawing, the reader's refusals.
    pub fn from_upload(&self, upload: Option<&[u8]>) -> Result<Option<Self>, crate::error::SolverError> {
        match self {
            Self::Drawing { units, layer, island, join_tolerance, chord_tolerance, corner_angle_deg } => {
                let drawing = Drawing {
                    units: *units,
                    layer: layer.clone(),
                    island: *island,
                    join_tolerance: *join_tolerance,
                    chord_tolerance: *chord_tolerance,
                };
                drawing.curve(upload, "curve", *corner_angle_deg).map(Some)
            }
            _ if upload.is_some() => Err(crate::error::SolverError::input(
                "drawing",
                "a DXF file was uploaded but curve.kind is not \"drawing\"",
            )),
            _ => Ok(None),
        }
    }
}
