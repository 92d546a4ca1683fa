//! The cut stock as a triangle mesh in binary glTF (docs/spec/verify.md §8 Mesh): every material
//! interval of every dexel ray as a column of its cell, the faces two neighbouring columns share
//! left out, coplanar neighbours of equal shade merged into one quad; each vertex coloured by the
//! signed deviation from the part along the ray and carrying it as `_DEVIATION`, or without a part
//! by whether the program cut its face.

use serde_json::{Value, json};

use crate::capability::{Run, too_large_answer};
use crate::error::{ErrorCode, SolverError};
use crate::tool::Tool;
use crate::units::{Scale, Units};

use super::capability::VerifyAnswer;
use super::dexel::{self, Field, Interval};
use super::job::Found;
use super::request::VerifyRequest;
use super::simulate;
use super::solid::SolidModel;

/// Media type of the mesh answer.
pub const GLB_MEDIA_TYPE: &str = "model/gltf-binary";

// glTF vertex colours are linear RGB: each is the sRGB colour named, linearised.
/// Colour of a surface whose deviation is a gouge deeper than the tolerance: red, sRGB #d62728.
pub const GOUGE_COLOUR: [u8; 4] = [171, 5, 5, 255];
/// Colour of a surface with material left thicker than the allowance: blue, sRGB #1f77b4.
pub const LEFT_COLOUR: [u8; 4] = [3, 47, 116, 255];
/// Colour of a surface within tolerance and allowance, and without a part of the stock's surface
/// as given: grey, sRGB #b0b0b0.
pub const NEUTRAL_COLOUR: [u8; 4] = [111, 111, 111, 255];
/// Colour of a surface the program cut, without a part: green, sRGB #2ca02c.
pub const CUT_COLOUR: [u8; 4] = [6, 90, 6, 255];
/// `extras.colouring` of a mesh without a part: its colours say what the program cut.
const CUT_COLOURING: &str = "cut";

/// Quads one interval of one ray may need before merging, for the bound checked before cutting:
/// its top, its bottom and a wall to each of two neighbours (the other two walls are counted by
/// the neighbours).
const QUADS_PER_INTERVAL: u64 = 4;

/// Bytes of the binary chunk one quad takes: four vertices (position, normal, colour, and with a
/// part the deviation) and two triangles of `u32` indices.
fn quad_bytes(deviation: bool) -> u64 {
    4 * (12 + 12 + 4 + if deviation { 4 } else { 0 }) + 6 * 4
}

/// The triangles as they are built, in glTF's attribute layout.
#[derive(Debug, Default)]
struct Mesh {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    colours: Vec<[u8; 4]>,
    deviations: Vec<f32>,
    indices: Vec<u32>,
}

/// What the faces of the cut stock are coloured against, on the stock's grid.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Against<'a> {
    /// The part: each interval's signed deviation from it (§8 Deviation), a face's shade, carried
    /// as `_DEVIATION`.
    Part { part: &'a Field, tolerance: f64, allowance: f64 },
    /// The stock as given, when there is no part: a face's shade is 1 where the program cut it
    /// (the given stock had material beyond it), else 0; no `_DEVIATION`.
    Given(&'a Field),
}

impl Against<'_> {
    fn part(&self) -> bool {
        matches!(self, Self::Part { .. })
    }

    fn colour(&self, shade: f64) -> [u8; 4] {
        match *self {
            Self::Part { tolerance, .. } if shade < -tolerance => GOUGE_COLOUR,
            Self::Part { allowance, .. } if shade > allowance => LEFT_COLOUR,
            Self::Given(_) if shade > 0.0 => CUT_COLOUR,
            _ => NEUTRAL_COLOUR,
        }
    }
}

/// Adds `colouring: "cut"` to the `extras` of a mesh without a part (an object, as every caller
/// builds it).
fn say_colouring(extras: &mut Value, against: &Against<'_>) {
    if let (Value::Object(fields), Against::Given(_)) = (extras, against) {
        fields.insert("colouring".to_owned(), Value::from(CUT_COLOURING));
    }
}

/// Whether the given stock `given` (one ray) had material just above `top`: the program cut the
/// top face there.
fn cut_above(top: f64, given: &[Interval]) -> bool {
    given.iter().any(|&[c, d]| c <= top && top < d)
}

/// Whether the given stock `given` (one ray) had material just below `bottom`.
fn cut_below(bottom: f64, given: &[Interval]) -> bool {
    given.iter().any(|&[c, d]| c < bottom && bottom <= d)
}

/// The shade of a face without a part: 1 cut, 0 as given.
fn shade_of(cut: bool) -> f64 {
    if cut { 1.0 } else { 0.0 }
}

impl Mesh {
    /// A quad with its corners counter-clockwise seen from outside (along `normal`).
    fn quad(&mut self, corners: [[f64; 3]; 4], normal: [f32; 3], shade: f64, against: &Against<'_>) {
        // A mesh too large for u32 indices is refused by the byte budget long before.
        let first = self.positions.len() as u32;
        let colour = against.colour(shade);
        for corner in corners {
            self.positions.push(corner.map(|v| v as f32));
            self.normals.push(normal);
            self.colours.push(colour);
            if against.part() {
                self.deviations.push(shade as f32);
            }
        }
        self.indices.extend([first, first + 1, first + 2, first, first + 2, first + 3]);
    }

    fn quads(&self) -> usize {
        self.indices.len() / 6
    }
}

/// The signed deviation of the stock interval `piece` from the part's intervals on the same ray,
/// mm along the ray: minus the part material missing at either end of the piece (a gouge), or the
/// thickest piece of it outside the part (material left), whichever is larger.
fn deviation(piece: Interval, part: &[Interval]) -> f64 {
    let [low, high] = piece;
    let mut gouge: f64 = 0.0;
    for &[c, d] in part {
        if c <= high && high < d {
            gouge = gouge.max(d - high);
        }
        if c < low && low <= d {
            gouge = gouge.max(low - c);
        }
    }
    let mut outside = Vec::new();
    dexel::outside(&[piece], part, 0.0, &mut outside);
    let left = outside.iter().map(|[a, b]| b - a).fold(0.0, f64::max);
    if gouge >= left { -gouge } else { left }
}

/// A strip of equal faces along one grid direction, merged into one quad when it ends.
#[derive(Debug, Clone, Copy)]
struct Strip {
    first: usize,
    last: usize,
    low: f64,
    high: f64,
    /// The faces' shade ([`Against`]).
    shade: f64,
    facing: bool,
}

impl Strip {
    fn same(&self, low: f64, high: f64, shade: f64, facing: bool) -> bool {
        self.low.to_bits() == low.to_bits()
            && self.high.to_bits() == high.to_bits()
            && self.shade.to_bits() == shade.to_bits()
            && self.facing == facing
    }
}

/// Open runs of one line of cells: extended by the next cell's equal faces, closed (handed to
/// `emit`) when a cell has none.
#[derive(Debug, Default)]
struct Strips {
    open: Vec<Strip>,
    closed: Vec<Strip>,
}

impl Strips {
    fn add(&mut self, at: usize, low: f64, high: f64, shade: f64, facing: bool) {
        if let Some(run) = self.open.iter_mut().find(|run| run.last + 1 == at && run.same(low, high, shade, facing)) {
            run.last = at;
        } else {
            self.open.push(Strip { first: at, last: at, low, high, shade, facing });
        }
    }

    /// Closes the runs not extended to cell `at`.
    fn close_before(&mut self, at: usize) {
        let (kept, ended): (Vec<Strip>, Vec<Strip>) = self.open.drain(..).partition(|run| run.last >= at);
        self.open = kept;
        self.closed.extend(ended);
    }

    fn finish(&mut self) -> Vec<Strip> {
        self.closed.append(&mut self.open);
        std::mem::take(&mut self.closed)
    }
}

/// The surface of `stock`, its faces shaded against the part or the stock as given.
struct Surface<'a> {
    stock: &'a Field,
    against: Against<'a>,
    mesh: Mesh,
}

impl Surface<'_> {
    fn ray(&self, i: usize, j: usize) -> &[Interval] {
        &self.stock.rays[self.stock.index(i, j)]
    }

    /// The ray of the part or the given stock at cell `(i, j)`.
    fn reference(&self, i: usize, j: usize) -> &[Interval] {
        let (Against::Part { part: field, .. } | Against::Given(field)) = self.against;
        &field.rays[field.index(i, j)]
    }

    /// The shades of the top and the bottom face of `piece` of ray `(i, j)`.
    fn ends(&self, i: usize, j: usize, piece: Interval) -> [f64; 2] {
        let reference = self.reference(i, j);
        match self.against {
            Against::Part { .. } => [deviation(piece, reference); 2],
            Against::Given(_) => [shade_of(cut_above(piece[1], reference)), shade_of(cut_below(piece[0], reference))],
        }
    }

    /// The tops and bottoms of row `j`, merged along x.
    fn row(&mut self, j: usize) {
        let grid = self.stock.grid;
        let mut runs = Strips::default();
        for i in 0..grid.nx {
            for &piece in self.ray(i, j) {
                let [top, bottom] = self.ends(i, j, piece);
                runs.add(i, piece[1], piece[1], top, true);
                runs.add(i, piece[0], piece[0], bottom, false);
            }
            runs.close_before(i);
        }
        let h = grid.spacing;
        let (y0, y1) = (grid.origin[1] + j as f64 * h, grid.origin[1] + (j + 1) as f64 * h);
        for run in runs.finish() {
            let x0 = grid.origin[0] + run.first as f64 * h;
            let x1 = grid.origin[0] + (run.last + 1) as f64 * h;
            let z = run.low;
            let [a, b, c, d] = [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]];
            if run.facing {
                self.mesh.quad([a, b, c, d], [0.0, 0.0, 1.0], run.shade, &self.against);
            } else {
                self.mesh.quad([a, d, c, b], [0.0, 0.0, -1.0], run.shade, &self.against);
            }
        }
    }

    /// The walls between column `wall − 1` and `wall` of cells along x (`across_x`) or between row
    /// `wall − 1` and `wall` along y, merged along the wall; a cell outside the grid is empty.
    fn wall(&mut self, wall: usize, across_x: bool) {
        let grid = self.stock.grid;
        let (count, along) = if across_x { (grid.nx, grid.ny) } else { (grid.ny, grid.nx) };
        let cell = |k: usize, at: usize| if across_x { (k, at) } else { (at, k) };
        let mut runs = Strips::default();
        let (mut pieces, mut kept, mut cut) = (Vec::new(), Vec::new(), Vec::new());
        for at in 0..along {
            let before = wall.checked_sub(1).map(|k| cell(k, at));
            let after = (wall < count).then(|| cell(wall, at));
            let material = |side: Option<(usize, usize)>| side.map_or(&[][..], |(i, j)| self.ray(i, j));
            for (from, to, facing) in [(before, after, true), (after, before, false)] {
                let Some((i, j)) = from else { continue };
                for &piece in material(from) {
                    pieces.clear();
                    dexel::outside(&[piece], material(to), 0.0, &mut pieces);
                    if pieces.is_empty() {
                        continue;
                    }
                    match self.against {
                        Against::Part { .. } => {
                            let deviation = deviation(piece, self.reference(i, j));
                            for &[low, high] in &pieces {
                                runs.add(at, low, high, deviation, facing);
                            }
                        }
                        Against::Given(_) => {
                            // A wall is cut where the neighbour's given stock stood against it.
                            let given = to.map_or(&[][..], |(i, j)| self.reference(i, j));
                            kept.clear();
                            cut.clear();
                            dexel::outside(&pieces, given, 0.0, &mut kept);
                            dexel::outside(&pieces, &kept, 0.0, &mut cut);
                            for (shaded, shade) in [(&kept, 0.0), (&cut, 1.0)] {
                                for &[low, high] in shaded {
                                    runs.add(at, low, high, shade, facing);
                                }
                            }
                        }
                    }
                }
            }
            runs.close_before(at);
        }
        let h = grid.spacing;
        let axis = usize::from(!across_x);
        let position = grid.origin[axis] + wall as f64 * h;
        for run in runs.finish() {
            let s0 = grid.origin[1 - axis] + run.first as f64 * h;
            let s1 = grid.origin[1 - axis] + (run.last + 1) as f64 * h;
            let (lo, hi) = (run.low, run.high);
            if across_x {
                let [a, b, c, d] = [[position, s0, lo], [position, s1, lo], [position, s1, hi], [position, s0, hi]];
                if run.facing {
                    self.mesh.quad([a, b, c, d], [1.0, 0.0, 0.0], run.shade, &self.against);
                } else {
                    self.mesh.quad([a, d, c, b], [-1.0, 0.0, 0.0], run.shade, &self.against);
                }
            } else {
                let [a, b, c, d] = [[s0, position, lo], [s0, position, hi], [s1, position, hi], [s1, position, lo]];
                if run.facing {
                    self.mesh.quad([a, b, c, d], [0.0, 1.0, 0.0], run.shade, &self.against);
                } else {
                    self.mesh.quad([a, d, c, b], [0.0, -1.0, 0.0], run.shade, &self.against);
                }
            }
        }
    }
}

/// The surface of `stock` as a mesh, charged to `run`'s budget line by line.
fn surface(stock: &Field, against: Against<'_>, run: &Run<'_>) -> Result<Mesh, SolverError> {
    let grid = stock.grid;
    let mut surface = Surface { stock, against, mesh: Mesh::default() };
    let lines = grid.ny + (grid.nx + 1) + (grid.ny + 1);
    let quad = quad_bytes(against.part());
    let mut charged = 0;
    let mut charge = |surface: &Surface<'_>, done: usize| -> Result<(), SolverError> {
        let quads = surface.mesh.quads();
        let result = run.charge((quads - charged) as u64 * quad, done, lines);
        charged = quads;
        result.map_err(|error| error.at("resolution"))
    };
    let mut done = 0;
    for j in 0..grid.ny {
        run.control.check()?;
        surface.row(j);
        done += 1;
        charge(&surface, done)?;
    }
    for wall in 0..=grid.nx {
        run.control.check()?;
        surface.wall(wall, true);
        done += 1;
        charge(&surface, done)?;
    }
    for wall in 0..=grid.ny {
        run.control.check()?;
        surface.wall(wall, false);
        done += 1;
        charge(&surface, done)?;
    }
    Ok(surface.mesh)
}

/// Appends `values` to `bin` as little-endian bytes; its view (offset, length) in the buffer.
fn append<const N: usize, T: Copy>(bin: &mut Vec<u8>, values: &[T], bytes: impl Fn(T) -> [u8; N]) -> (usize, usize) {
    let offset = bin.len();
    for &value in values {
        bin.extend_from_slice(&bytes(value));
    }
    (offset, bin.len() - offset)
}

/// `mesh` as a GLB file: the glTF JSON (with `extras`) and the binary chunk.
fn glb(mesh: &Mesh, extras: Value) -> Vec<u8> {
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    const FLOAT: u32 = 5126;
    const UNSIGNED_BYTE: u32 = 5121;
    const UNSIGNED_INT: u32 = 5125;
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let count = mesh.positions.len();
    let mut attributes = serde_json::Map::new();
    let mut view = |(offset, length): (usize, usize), target: u32| {
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": length, "target": target}));
        views.len() - 1
    };
    let vec3 = |v: [f32; 3]| {
        let mut out = [0u8; 12];
        for k in 0..3 {
            out[4 * k..4 * k + 4].copy_from_slice(&v[k].to_le_bytes());
        }
        out
    };
    let mut primitive = json!({"mode": 4, "material": 0});
    if count > 0 {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in &mesh.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let at = append(&mut bin, &mesh.positions, vec3);
        let v = view(at, ARRAY_BUFFER);
        accessors.push(
            json!({"bufferView": v, "componentType": FLOAT, "count": count, "type": "VEC3", "min": lo, "max": hi}),
        );
        attributes.insert("POSITION".into(), json!(accessors.len() - 1));
        let at = append(&mut bin, &mesh.normals, vec3);
        let v = view(at, ARRAY_BUFFER);
        accessors.push(json!({"bufferView": v, "componentType": FLOAT, "count": count, "type": "VEC3"}));
        attributes.insert("NORMAL".into(), json!(accessors.len() - 1));
        let at = append(&mut bin, &mesh.colours, |c| c);
        let v = view(at, ARRAY_BUFFER);
        accessors.push(json!({"bufferView": v, "componentType": UNSIGNED_BYTE, "normalized": true, "count": count, "type": "VEC4"}));
        attributes.insert("COLOR_0".into(), json!(accessors.len() - 1));
        if !mesh.deviations.is_empty() {
            let (lo, hi) =
                mesh.deviations.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &d| (lo.min(d), hi.max(d)));
            let at = append(&mut bin, &mesh.deviations, f32::to_le_bytes);
            let v = view(at, ARRAY_BUFFER);
            accessors.push(json!({"bufferView": v, "componentType": FLOAT, "count": count, "type": "SCALAR", "min": [lo], "max": [hi]}));
            attributes.insert("_DEVIATION".into(), json!(accessors.len() - 1));
        }
        let at = append(&mut bin, &mesh.indices, u32::to_le_bytes);
        let v = view(at, ELEMENT_ARRAY_BUFFER);
        accessors.push(
            json!({"bufferView": v, "componentType": UNSIGNED_INT, "count": mesh.indices.len(), "type": "SCALAR"}),
        );
        primitive["indices"] = json!(accessors.len() - 1);
        primitive["attributes"] = Value::Object(attributes);
    }
    let mut document = json!({
        "asset": {"version": "2.0", "generator": "kerf verify"},
        "scene": 0,
        "scenes": [{"name": "cut stock", "nodes": if count > 0 { json!([0]) } else { json!([]) }}],
        "materials": [{"name": "stock", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}}],
        "extras": extras,
    });
    if count > 0 {
        document["nodes"] = json!([{"name": "cut stock", "mesh": 0}]);
        document["meshes"] = json!([{"name": "cut stock", "primitives": [primitive]}]);
        document["buffers"] = json!([{"byteLength": bin.len()}]);
        document["bufferViews"] = Value::Array(views);
        document["accessors"] = Value::Array(accessors);
    }
    // Serialising a `Value` cannot fail.
    let mut text = serde_json::to_vec(&document).unwrap_or_default();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    out
}

/// Cuts `request`'s program (in mm) with its resolved `tools` (moves on lines after `upto_line`
/// left out) and answers the stock as the program left it as GLB in `units` (positions and
/// `_DEVIATION`), the JSON answer in `units` in the glTF's `extras.verify`; without a part,
/// coloured by what the program cut (`extras.colouring`). With `upto_line`, a program that has not
/// reached the stock by then answers the stock as given, without `extras.verify`.
///
/// # Errors
/// As the JSON answer; `E_TOO_LARGE_ANSWER` at `resolution` when the mesh's bound, checked
/// before cutting, or the mesh as it is built passes the run's answer budget.
pub fn cut_stock_glb(
    request: &VerifyRequest,
    tools: Vec<Tool>,
    found: Found<'_>,
    upto_line: Option<usize>,
    units: Units,
    run: &Run<'_>,
) -> Result<Vec<u8>, SolverError> {
    let mut job = request.validate(&tools, found, run.upload, run.control)?;
    let intervals: u64 = if matches!(job.stock, SolidModel::Tube { .. }) { 2 } else { 1 };
    let bound = job.grid.len() as u64 * intervals * QUADS_PER_INTERVAL * quad_bytes(job.part.is_some());
    if let Some(budget) = run.budget
        && bound > budget.limit()
    {
        return Err(too_large_answer(bound, budget.limit()).at("resolution"));
    }
    if let Some(last) = upto_line {
        job.program.moves.retain(|read| read.line <= last);
    }
    let (mut extras, stock) = match simulate::cut_stock(&job, run) {
        Ok((cut, stock)) => {
            let mut answer = VerifyAnswer::new(tools, cut);
            if let Some(scaling) = units.from_mm() {
                answer.scale(scaling);
            }
            let mut answer = serde_json::to_value(answer)
                .map_err(|error| SolverError::new(ErrorCode::Internal, error.to_string()))?;
            // As the JSON answer, which names its units first.
            if let Value::Object(fields) = &mut answer {
                fields.insert("units".to_owned(), Value::from(units.as_str()));
            }
            (json!({"verify": answer}), stock)
        }
        Err(error) if upto_line.is_some() && error.code() == ErrorCode::Stock => (json!({}), job.stock.field(job.grid)),
        Err(error) => return Err(error),
    };
    // Against the part, or without one the stock as given.
    let reference = job.part.as_ref().unwrap_or(&job.stock).field(job.grid);
    let against = if job.part.is_some() {
        Against::Part { part: &reference, tolerance: job.tolerance, allowance: job.allowance }
    } else {
        Against::Given(&reference)
    };
    say_colouring(&mut extras, &against);
    let mut mesh = surface(&stock, against, run)?;
    run.control.check()?;
    mesh.restate(units);
    Ok(glb(&mesh, extras))
}

impl Mesh {
    /// Positions and deviations in `units` (built in mm; the colours were chosen in mm).
    fn restate(&mut self, units: Units) {
        let Some(scaling) = units.from_mm() else { return };
        for position in &mut self.positions {
            *position = position.map(|v| scaling.apply(f64::from(v)) as f32);
        }
        for deviation in &mut self.deviations {
            *deviation = scaling.apply(f64::from(*deviation)) as f32;
        }
    }
}

/// `stock` as a capability's own verification left it (docs/spec/verify.md §9.4), coloured
/// `against` the part or the stock as modelled on the same grid, as GLB in `units` with `extras`
/// (with `colouring` added without a part; the caller checks the bound, [`mesh_bound`], before
/// cutting).
///
/// # Errors
/// `E_TOO_LARGE_ANSWER` at `verification.resolution` over the run's answer budget.
pub(crate) fn fields_glb(
    stock: &Field,
    against: Against<'_>,
    mut extras: Value,
    units: Units,
    run: &Run<'_>,
) -> Result<Vec<u8>, SolverError> {
    say_colouring(&mut extras, &against);
    let mut mesh = surface(stock, against, run).map_err(|error| {
        if error.field() == Some("resolution") { error.at("verification.resolution") } else { error }
    })?;
    run.control.check()?;
    mesh.restate(units);
    Ok(glb(&mesh, extras))
}

/// The bound of the mesh of `rays` rays of `intervals` intervals each with a part (§8 Bound).
pub(crate) fn mesh_bound(rays: usize, intervals: u64) -> u64 {
    rays as u64 * intervals * QUADS_PER_INTERVAL * quad_bytes(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capability::AnswerBudget;
    use crate::tool::ToolRef;

    /// A GLB read back: its JSON and its binary chunk, checking the container on the way.
    fn read(bytes: &[u8]) -> (Value, Vec<u8>) {
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[0..4], b"glTF");
        assert_eq!(word(4), 2);
        assert_eq!(word(8), bytes.len());
        let length = word(12);
        assert_eq!(&bytes[16..20], b"JSON");
        let json: Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
        let at = 20 + length;
        if at == bytes.len() {
            return (json, Vec::new());
        }
        assert_eq!(&bytes[at + 4..at + 8], b"BIN\0");
        let bin = bytes[at + 8..at + 8 + word(at)].to_vec();
        assert_eq!(at + 8 + bin.len(), bytes.len());
        (json, bin)
    }

    /// The float values of accessor `index`.
    fn floats(json: &Value, bin: &[u8], index: usize) -> Vec<f32> {
        let accessor = &json["accessors"][index];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        let length = view["byteLength"].as_u64().unwrap() as usize;
        bin[offset..offset + length].chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect()
    }

    fn indices(json: &Value, bin: &[u8], index: usize) -> Vec<u32> {
        let view = &json["bufferViews"][json["accessors"][index]["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        let length = view["byteLength"].as_u64().unwrap() as usize;
        bin[offset..offset + length].chunks(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect()
    }

    fn glb_of(body: Value, upto_line: Option<usize>) -> Vec<u8> {
        let request: VerifyRequest = serde_json::from_value(body).unwrap();
        let tools = request
            .tools
            .iter()
            .map(|tool| match tool {
                ToolRef::Inline(tool) => tool.clone(),
                ToolRef::Number(_) => panic!("inline tools only"),
            })
            .collect();
        cut_stock_glb(&request, tools, Found::default(), upto_line, Units::Mm, &Run::default()).expect("a mesh")
    }

    /// The slot of `tests.rs` with a part 1.9 below the top, cut to 2: a gouge of 0.1 along the slot,
    /// 1.9 of material left beside it.
    fn slot() -> Value {
        json!({
            "program": "G21 G90\nG0 X0 Y0 Z5\nG1 Z-2 F300\nG1 X50 F600\nG0 Z5\nM30",
            "tools": [{"kind": "flat", "radius": 5}],
            "stock": {"kind": "box", "min": [-20, -20, -10], "max": [70, 20, 0]},
            "part": {"kind": "box", "min": [-20, -20, -10], "max": [70, 20, -1.9]},
            "resolution": 0.5,
        })
    }

    /// Signed volume of the closed triangle mesh (divergence theorem), mm³.
    fn volume(positions: &[f32], triangles: &[u32]) -> f64 {
        let p = |k: u32| {
            let at = 3 * k as usize;
            [f64::from(positions[at]), f64::from(positions[at + 1]), f64::from(positions[at + 2])]
        };
        triangles
            .chunks(3)
            .map(|t| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    #[test]
    fn the_mesh_encloses_the_volume_the_answer_reports_and_colours_the_gouge() {
        let bytes = glb_of(slot(), None);
        let (json, bin) = read(&bytes);
        let answer = &json["extras"]["verify"];
        let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
        let positions = floats(&json, &bin, attributes["POSITION"].as_u64().unwrap() as usize);
        let triangles = indices(&json, &bin, json["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize);
        let enclosed = volume(&positions, &triangles);
        let reported = answer["final_volume_mm3"].as_f64().unwrap();
        assert!((enclosed / reported - 1.0).abs() < 1e-6, "{enclosed} against {reported}");
        let position = &json["accessors"][attributes["POSITION"].as_u64().unwrap() as usize];
        assert_eq!(position["min"], json!([-20.0, -20.0, -10.0]));
        assert_eq!(position["max"], json!([70.0, 20.0, 0.0]));
        // Every vertex of the slot's floor is a gouge of 0.1 (merged strips put them at the
        // floor's edges); the uncut top is 1.9 of material left.
        let deviations = floats(&json, &bin, attributes["_DEVIATION"].as_u64().unwrap() as usize);
        let colours_view = &json["bufferViews"]
            [json["accessors"][attributes["COLOR_0"].as_u64().unwrap() as usize]["bufferView"].as_u64().unwrap()
                as usize];
        let colours = &bin[colours_view["byteOffset"].as_u64().unwrap() as usize..];
        let normals = floats(&json, &bin, attributes["NORMAL"].as_u64().unwrap() as usize);
        let mut floor = 0;
        for (k, &deviation) in deviations.iter().enumerate() {
            let (x, y, z) = (positions[3 * k], positions[3 * k + 1], positions[3 * k + 2]);
            let colour = &colours[4 * k..4 * k + 4];
            if normals[3 * k + 2] != 1.0 {
                continue;
            }
            if z == -2.0 {
                floor += 1;
                assert!((f64::from(deviation) + 0.1).abs() < 1e-5, "{deviation} at {x} {y}");
                assert_eq!(colour, GOUGE_COLOUR);
            }
            if z == 0.0 {
                assert!((f64::from(deviation) - 1.9).abs() < 1e-5, "{deviation} at {x} {y}");
                assert_eq!(colour, LEFT_COLOUR);
            }
        }
        assert!(floor > 0, "no vertex on the slot's floor");
    }

    #[test]
    fn playback_cuts_up_to_a_line() {
        let whole = read(&glb_of(slot(), None)).0;
        let plunged = read(&glb_of(slot(), Some(3))).0;
        let before = read(&glb_of(slot(), Some(2))).0;
        let removed = |json: &Value| json["extras"]["verify"]["removed_volume_mm3"].as_f64().unwrap();
        assert!(removed(&plunged) > 0.0 && removed(&plunged) < removed(&whole) / 5.0);
        assert_eq!(before["extras"], json!({}), "nothing cut by line 2");
        assert!(before["accessors"][0]["count"].as_u64().unwrap() > 0);
    }

    #[test]
    fn a_mesh_over_the_budget_is_refused_before_cutting() {
        let request: VerifyRequest = serde_json::from_value(slot()).unwrap();
        let tools = vec![Tool { ..serde_json::from_value(json!({"kind": "flat", "radius": 5})).unwrap() }];
        let budget = AnswerBudget::new(100_000);
        let run = Run { budget: Some(&budget), ..Run::default() };
        let error = cut_stock_glb(&request, tools, Found::default(), None, Units::Mm, &run).unwrap_err();
        assert_eq!(error.code(), ErrorCode::TooLargeAnswer);
        assert_eq!(error.field(), Some("resolution"));
        assert_eq!(budget.used(), 0, "refused before anything was built");
    }

    #[test]
    fn without_a_part_the_faces_the_program_cut_are_green() {
        let mut body = slot();
        body.as_object_mut().unwrap().remove("part");
        let (json, bin) = read(&glb_of(body.clone(), None));
        assert_eq!(json["extras"]["colouring"], "cut");
        let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
        assert!(attributes.get("_DEVIATION").is_none(), "{attributes}");
        let positions = floats(&json, &bin, attributes["POSITION"].as_u64().unwrap() as usize);
        let normals = floats(&json, &bin, attributes["NORMAL"].as_u64().unwrap() as usize);
        let view = &json["bufferViews"]
            [json["accessors"][attributes["COLOR_0"].as_u64().unwrap() as usize]["bufferView"].as_u64().unwrap()
                as usize];
        let colours = &bin[view["byteOffset"].as_u64().unwrap() as usize..];
        let (mut floor, mut walls) = (0, 0);
        for k in 0..positions.len() / 3 {
            let (x, y, z) = (positions[3 * k], positions[3 * k + 1], positions[3 * k + 2]);
            let colour = &colours[4 * k..4 * k + 4];
            let normal = &normals[3 * k..3 * k + 3];
            if normal[2] == 1.0 && z == -2.0 {
                floor += 1;
                assert_eq!(colour, CUT_COLOUR, "the slot's floor at {x} {y}");
            } else if normal[2] == 1.0 && z == 0.0 {
                assert_eq!(colour, NEUTRAL_COLOUR, "the block's top at {x} {y}");
            } else if (normal[1].abs() == 1.0 && y.abs() == 20.0) || normal[2] == -1.0 {
                assert_eq!(colour, NEUTRAL_COLOUR, "the block's outer wall or bottom at {x} {y} {z}");
            } else if normal[1].abs() == 1.0 && z > -2.0 && y.abs() < 6.0 {
                walls += 1;
                assert_eq!(colour, CUT_COLOUR, "the slot's wall at {x} {y} {z}");
            }
        }
        assert!(floor > 0 && walls > 0, "floor {floor}, walls {walls}");
        // Before the plunge: the stock as given, all grey, still said to have no part.
        let (before, bin) = read(&glb_of(body, Some(2)));
        assert_eq!(before["extras"], json!({"colouring": "cut"}));
        let view = &before["bufferViews"][before["accessors"][2]["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(before["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"], 2);
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        let length = view["byteLength"].as_u64().unwrap() as usize;
        assert!(bin[offset..offset + length].chunks(4).all(|c| c == NEUTRAL_COLOUR));
    }

    #[test]
    fn deviation_is_signed_along_the_ray() {
        assert!((deviation([-10.0, -2.0], &[[-10.0, -1.9]]) + 0.1).abs() < 1e-12);
        assert_eq!(deviation([-10.0, 0.0], &[[-10.0, -2.0]]), 2.0);
        assert_eq!(deviation([-10.0, -2.0], &[[-10.0, -2.0]]), 0.0);
        assert_eq!(deviation([1.0, 2.0], &[]), 1.0);
        let tube_wall = deviation([6.0, 10.0], &[[-10.0, -6.0], [6.5, 10.0]]);
        assert!((tube_wall - 0.5).abs() < 1e-12, "{tube_wall}");
    }
}
