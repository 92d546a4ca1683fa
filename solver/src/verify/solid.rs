//! The stock and the part as solids on the dexel grid (docs/spec/verify.md §3 Stock model):
//! predict's box, cylinder, height grid and STL mesh (validated and read by predict's own model),
//! and the tube with its cross holes; each gives the intervals of z it holds on a vertical ray.

use crate::error::SolverError;
use crate::geometry::{Vec3, vec3};
use crate::stock::Stock;
use crate::stock::StockModel;
use crate::stock::stl::{self, Mesh};
use crate::validate::{Measure, coordinate, coordinates, positive};

use super::dexel::{self, Field, Grid, Interval, Ray};
use super::request::{CrossHole, Hollow, MAX_CROSS_HOLES, Solid};

/// A segment of an axis: from `start` along the unit `axis` for `length`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Axis {
    pub(crate) start: Vec3,
    pub(crate) axis: Vec3,
    pub(crate) length: f64,
}

/// A validated solid.
#[derive(Debug, Clone)]
pub(crate) enum SolidModel {
    /// Box, cylinder, height grid with a bottom, or a closed mesh.
    Stock(StockModel),
    /// A cylinder of `outer` radius minus the same of `inner` radius and minus each cross hole
    /// (an axis and its radius).
    Tube { axis: Axis, outer: f64, inner: f64, holes: Vec<(Axis, f64)> },
}

/// The axis between `start` and `end` given at fields `{field}.start` and `{field}.end`.
fn axis(field: &str, start: [f64; 3], end: [f64; 3]) -> Result<Axis, SolverError> {
    let a = vec3(coordinates(&format!("{field}.start"), start)?);
    let b = vec3(coordinates(&format!("{field}.end"), end)?);
    let length = (b - a).norm();
    if length == 0.0 {
        return Err(SolverError::input(format!("{field}.end"), "the axis's end equals its start"));
    }
    Ok(Axis { start: a, axis: (b - a) / length, length })
}

/// The closed, outward-oriented mesh of the STL file `bytes` given for the solid at `prefix`:
/// predict's reading and closedness check, and a positive enclosed volume.
fn mesh(bytes: &[u8], units: crate::units::Units, prefix: &str) -> Result<Mesh, SolverError> {
    let triangles = stl::parse_in(bytes, units).map_err(|error| renamed(error, prefix))?;
    stl::check_closed(&triangles).map_err(|error| renamed(error, prefix))?;
    let volume = stl::signed_volume(&triangles);
    if volume <= 0.0 {
        return Err(SolverError::input(
            prefix,
            format!(
                "the {prefix}'s mesh is inside out: the volume its triangles enclose is {volume:.6} mm³, so their \
                 normals point inward; reverse the order of every triangle's vertices"
            ),
        ));
    }
    Ok(Mesh::new(&triangles))
}

/// `error` with its field moved from predict's `stock.` to `prefix` (`part`).
fn renamed(error: SolverError, prefix: &str) -> SolverError {
    match error.field().map(|field| field.replacen("stock", prefix, 1)) {
        Some(field) => error.at(field),
        None => error,
    }
}

impl Solid {
    /// Validates the solid given at request field `prefix` (`stock` or `part`); `upload` is its
    /// STL file when it is a `mesh`.
    pub(crate) fn model(&self, prefix: &str, upload: Option<&[u8]>) -> Result<SolidModel, SolverError> {
        let field = |name: &str| format!("{prefix}.{name}");
        match self {
            Self::Tube(Hollow::Tube { start, end, outer_radius, inner_radius, holes }) => {
                let tube = axis(prefix, *start, *end)?;
                let outer = coordinate(
                    &field("outer_radius"),
                    positive(&field("outer_radius"), *outer_radius, Measure::Length)?,
                )?;
                let inner = positive(&field("inner_radius"), *inner_radius, Measure::Length)?;
                if inner >= outer {
                    return Err(SolverError::input(
                        field("inner_radius"),
                        format!(
                            "inner_radius {} must be smaller than outer_radius {}",
                            Measure::Length.quote(inner),
                            Measure::Length.quote(outer)
                        ),
                    ));
                }
                if holes.len() > MAX_CROSS_HOLES {
                    return Err(SolverError::input(
                        field("holes"),
                        format!("at most {MAX_CROSS_HOLES} cross holes (got {})", holes.len()),
                    ));
                }
                let holes = holes
                    .iter()
                    .enumerate()
                    .map(|(index, CrossHole { start, end, radius })| {
                        let hole = field(&format!("holes[{index}]"));
                        let radius = coordinate(
                            &format!("{hole}.radius"),
                            positive(&format!("{hole}.radius"), *radius, Measure::Length)?,
                        )?;
                        Ok((axis(&hole, *start, *end)?, radius))
                    })
                    .collect::<Result<_, SolverError>>()?;
                Ok(SolidModel::Tube { axis: tube, outer, inner, holes })
            }
            Self::Stock(Stock::Plane { .. }) => Err(SolverError::input(
                field("kind"),
                "a plane has no bottom, so its volume is unbounded: give a box or a grid with a bottom",
            )),
            Self::Stock(Stock::Mesh { units }) => match upload {
                Some(bytes) => {
                    Ok(SolidModel::Stock(StockModel::Mesh(Box::new(mesh(bytes, units.unwrap_or_default(), prefix)?))))
                }
                None => Err(SolverError::input(
                    prefix,
                    format!("a mesh {prefix} needs its STL file uploaded with the request (form part `{prefix}`)"),
                )),
            },
            Self::Stock(stock @ Stock::Grid { bottom: None, .. }) => {
                stock.model(None).map_err(|error| renamed(error, prefix))?;
                Err(SolverError::input(field("bottom"), "a grid needs a bottom here: its volume is counted"))
            }
            Self::Stock(stock) => Ok(SolidModel::Stock(stock.model(None).map_err(|error| renamed(error, prefix))?)),
        }
    }
}

/// The interval of z on the vertical line through `(x, y)` within `radius` of the segment from
/// `start` along the unit `axis` for `length`.
fn cylinder_interval(x: f64, y: f64, Axis { start, axis, length }: &Axis, radius: f64) -> Option<Interval> {
    let length = *length;
    // A point (x, y, start.z + w) is within `radius` of the axis line where
    // (1 − a_z²)·w² − 2·k·a_z·w + (c − k² − r²) ≤ 0, and between the end planes where
    // 0 ≤ k + a_z·w ≤ length (k, c: the axial and squared horizontal offsets at w = 0).
    let (dx, dy) = (x - start.x, y - start.y);
    let k = dx * axis.x + dy * axis.y;
    let c = dx * dx + dy * dy;
    let a = 1.0 - axis.z * axis.z;
    let b = -2.0 * k * axis.z;
    let constant = c - k * k - radius * radius;
    let (mut low, mut high) = if a > 1e-12 {
        let discriminant = b * b - 4.0 * a * constant;
        if discriminant <= 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a))
    } else if constant < 0.0 {
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        return None;
    };
    if axis.z.abs() > 1e-12 {
        let (p, q) = ((-k) / axis.z, (length - k) / axis.z);
        low = low.max(p.min(q));
        high = high.min(p.max(q));
    } else if !(0.0..=length).contains(&k) {
        return None;
    }
    (high > low).then_some([start.z + low, start.z + high])
}

impl SolidModel {
    /// The xy rectangle holding the solid.
    pub(crate) fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::Stock(model) => model.footprint(),
            Self::Tube { axis: Axis { start, axis, length }, outer, .. } => {
                StockModel::Cylinder { start: *start, axis: *axis, length: *length, radius: *outer }.footprint()
            }
        }
    }

    /// The material on the vertical ray through `(x, y)`, sorted; `heights` is scratch space.
    pub(crate) fn ray(&self, x: f64, y: f64, heights: &mut Vec<f64>) -> Ray {
        let mut ray = Ray::new();
        match self {
            Self::Stock(StockModel::Box { lo, hi }) => {
                if x > lo.x && x < hi.x && y > lo.y && y < hi.y {
                    ray.push([lo.z, hi.z]);
                }
            }
            Self::Stock(StockModel::Cylinder { start, axis, length, radius }) => {
                ray.extend(cylinder_interval(x, y, &Axis { start: *start, axis: *axis, length: *length }, *radius));
            }
            Self::Stock(StockModel::Grid(grid)) => {
                if let Some(top) = grid.top_at(x, y)
                    && top > grid.bottom()
                {
                    ray.push([grid.bottom(), top]);
                }
            }
            Self::Stock(StockModel::Mesh(mesh)) => {
                // A closed surface is crossed an even number of times: each pair bounds the solid
                // (an odd one left over, from a crossing at the very edge of a triangle the fill
                // rule gave away inconsistently, adds nothing).
                mesh.crossings(x, y, heights);
                for pair in heights.chunks_exact(2) {
                    if pair[1] > pair[0] {
                        ray.push([pair[0], pair[1]]);
                    }
                }
            }
            // Refused by `Solid::model`.
            Self::Stock(StockModel::Plane { .. }) => {}
            Self::Tube { axis, outer, inner, holes } => {
                if let Some(material) = cylinder_interval(x, y, axis, *outer) {
                    ray.push(material);
                    let mut removed = Vec::new();
                    let bores =
                        std::iter::once((axis, *inner)).chain(holes.iter().map(|(hole, radius)| (hole, *radius)));
                    for (bore, radius) in bores {
                        if let Some(cut) = cylinder_interval(x, y, bore, radius) {
                            dexel::subtract(&mut ray, cut, &mut removed);
                        }
                    }
                }
            }
        }
        ray
    }

    /// The solid on `grid`.
    pub(crate) fn field(&self, grid: Grid) -> Field {
        self.field_rows(grid, 0..grid.ny)
    }

    /// The solid on rows `rows` of `grid`.
    pub(crate) fn field_rows(&self, grid: Grid, rows: std::ops::Range<usize>) -> Field {
        let mut rays = Vec::with_capacity(grid.nx * rows.len());
        let mut heights = Vec::new();
        for j in rows.clone() {
            for i in 0..grid.nx {
                rays.push(self.ray(grid.x(i), grid.y(j), &mut heights));
            }
        }
        Field { grid, rows, rays }
    }
}

/// Refuses a `part` that holds no material on the grid or has material the `stock` does not
/// have, thicker than `tolerance` on a ray: a program cannot leave what the stock lacks, so the
/// part or the stock is in the wrong place.
pub(crate) fn check_part_in_stock(part: &Field, stock: &Field, tolerance: f64) -> Result<(), SolverError> {
    PartCheck::of(part, stock, tolerance).verdict()
}

/// What [`check_part_in_stock`] finds on some rows of the grid; the checks of consecutive rows
/// merge ([`PartCheck::merge`]) into the check of all of them.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct PartCheck {
    /// Whether the part holds no material on the rows.
    pub empty: bool,
    /// The thickest piece of the part outside the stock (the first of equals in row order), and
    /// where it starts.
    pub worst: Option<(f64, [f64; 3])>,
}

impl PartCheck {
    /// The check of the rows both fields hold (the same).
    pub fn of(part: &Field, stock: &Field, tolerance: f64) -> Self {
        let grid = stock.grid;
        let mut pieces = Vec::new();
        let mut check = Self { empty: true, worst: None };
        for (index, (part_ray, stock_ray)) in part.rays.iter().zip(&stock.rays).enumerate() {
            check.empty &= part_ray.is_empty();
            pieces.clear();
            dexel::outside(part_ray, stock_ray, 0.0, &mut pieces);
            for &[low, high] in &pieces {
                if high - low > tolerance && check.worst.is_none_or(|(thickest, _)| high - low > thickest) {
                    let (i, j) = stock.ray_at(index);
                    check.worst = Some((high - low, [grid.x(i), grid.y(j), low]));
                }
            }
        }
        check
    }

    /// The check of these rows and the `next` ones after them.
    pub fn merge(self, next: Self) -> Self {
        let worst = match (self.worst, next.worst) {
            (Some(first), Some(second)) if second.0 > first.0 => Some(second),
            (None, second) => second,
            (first, _) => first,
        };
        Self { empty: self.empty && next.empty, worst }
    }

    /// The refusal, if any.
    pub fn verdict(self) -> Result<(), SolverError> {
        if self.empty {
            return Err(SolverError::input(
                "part",
                "the part holds no material on the stock's dexel grid: is it in the stock?",
            ));
        }
        match self.worst {
            Some((thickness, [x, y, z])) => Err(SolverError::input(
                "part",
                format!(
                    "the part lies outside the stock: {thickness:.3} mm of it on the ray through x = {x:.3} mm, y = {y:.3} mm \
                     from z = {z:.3} mm is not stock material; place the part in the stock, in the program's coordinates"
                ),
            )),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(json: &str) -> SolidModel {
        serde_json::from_str::<Solid>(json).unwrap().model("stock", None).unwrap()
    }

    #[test]
    fn volumes_of_the_solids_converge() {
        let pi = std::f64::consts::PI;
        let cases = [
            (r#"{"kind": "box", "min": [0, 0, 0], "max": [10, 20, 3]}"#, 600.0),
            (r#"{"kind": "cylinder", "start": [0, 0, 0], "end": [0, 0, 10], "radius": 5}"#, 250.0 * pi),
            (r#"{"kind": "cylinder", "start": [0, 0, 0], "end": [20, 0, 0], "radius": 5}"#, 500.0 * pi),
            (
                r#"{"kind": "tube", "start": [-20, 0, 0], "end": [20, 0, 0], "outer_radius": 10, "inner_radius": 6}"#,
                40.0 * pi * 64.0,
            ),
            (
                r#"{"kind": "tube", "start": [0, 0, -5], "end": [3, 4, 5], "outer_radius": 4, "inner_radius": 2}"#,
                125f64.sqrt() * pi * 12.0,
            ),
        ];
        for (json, exact) in cases {
            let model = solid(json);
            let (lo, hi) = model.footprint();
            let volume = model.field(Grid::covering(lo, hi, 0.05)).volume();
            assert!((volume / exact - 1.0).abs() < 2e-3, "{json}: {volume} against {exact}");
        }
    }

    #[test]
    fn a_horizontal_tube_gives_two_intervals_through_its_bore() {
        let tube = solid(
            r#"{"kind": "tube", "start": [-20, 0, 0], "end": [20, 0, 0], "outer_radius": 10, "inner_radius": 6}"#,
        );
        let ray = tube.ray(0.0, 0.0, &mut Vec::new());
        assert_eq!(ray.len(), 2);
        assert!((ray[0][0] + 10.0).abs() < 1e-12 && (ray[0][1] + 6.0).abs() < 1e-12);
        assert!((ray[1][0] - 6.0).abs() < 1e-12 && (ray[1][1] - 10.0).abs() < 1e-12);
    }

    #[test]
    fn refused_solids_name_their_field() {
        let cases = [
            (
                r#"{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "min": [0, 0], "max": [1, 1]}"#,
                "part.kind",
            ),
            (r#"{"kind": "box", "min": [0, 0, 0], "max": [1, 1, 0]}"#, "part.max"),
            (r#"{"kind": "grid", "origin": [0, 0], "spacing": 1, "heights": [[0, 0], [0, 0]]}"#, "part.bottom"),
            (
                r#"{"kind": "tube", "start": [0, 0, 0], "end": [0, 0, 1], "outer_radius": 2, "inner_radius": 2}"#,
                "part.inner_radius",
            ),
        ];
        for (json, field) in cases {
            let error = serde_json::from_str::<Solid>(json).unwrap().model("part", None).unwrap_err();
            assert_eq!(error.field(), Some(field), "{json}");
        }
    }
}
