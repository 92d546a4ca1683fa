//! The stock and the part as solids on the dexel grid (docs/spec/verify.md §3 Stock model):
//! predict's box, cylinder and height grid (validated by predict's own model), and the tube; each
//! gives the intervals of z it holds on a vertical ray.

use crate::error::SolverError;
use crate::geometry::{Vec3, vec3};
use crate::predict::Stock;
use crate::predict::stock::StockModel;
use crate::validate::{coordinate, coordinates, positive};

use super::dexel::{Field, Grid, Interval, Ray};
use super::request::{Hollow, Solid};

/// A validated solid.
#[derive(Debug, Clone)]
pub(crate) enum SolidModel {
    /// Box, cylinder or height grid with a bottom.
    Stock(StockModel),
    /// A cylinder of `outer` radius minus the same of `inner` radius.
    Tube { start: Vec3, axis: Vec3, length: f64, outer: f64, inner: f64 },
}

/// `error` with its field moved from predict's `stock.` to `prefix` (`part`).
fn renamed(error: SolverError, prefix: &str) -> SolverError {
    match error.field().map(|field| field.replacen("stock", prefix, 1)) {
        Some(field) => error.at(field),
        None => error,
    }
}

impl Solid {
    /// Validates the solid given at request field `prefix` (`stock` or `part`).
    pub(crate) fn model(&self, prefix: &str) -> Result<SolidModel, SolverError> {
        let field = |name: &str| format!("{prefix}.{name}");
        match self {
            Self::Tube(Hollow::Tube { start, end, outer_radius, inner_radius }) => {
                let a = vec3(coordinates(&field("start"), *start)?);
                let b = vec3(coordinates(&field("end"), *end)?);
                let outer = coordinate(&field("outer_radius"), positive(&field("outer_radius"), *outer_radius)?)?;
                let inner = positive(&field("inner_radius"), *inner_radius)?;
                if inner >= outer {
                    return Err(SolverError::input(
                        field("inner_radius"),
                        format!("inner_radius {inner} must be smaller than outer_radius {outer}"),
                    ));
                }
                let length = (b - a).norm();
                if length == 0.0 {
                    return Err(SolverError::input(field("end"), "the tube's end equals its start"));
                }
                Ok(SolidModel::Tube { start: a, axis: (b - a) / length, length, outer, inner })
            }
            Self::Stock(Stock::Plane { .. }) => Err(SolverError::input(
                field("kind"),
                "a plane has no bottom, so its volume is unbounded: give a box or a grid with a bottom",
            )),
            Self::Stock(Stock::Mesh {}) => Err(SolverError::input(
                field("kind"),
                "verify takes no uploaded file: give a box, cylinder, tube or grid",
            )),
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
fn cylinder_interval(x: f64, y: f64, start: &Vec3, axis: &Vec3, length: f64, radius: f64) -> Option<Interval> {
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
            Self::Tube { start, axis, length, outer, .. } => {
                StockModel::Cylinder { start: *start, axis: *axis, length: *length, radius: *outer }.footprint()
            }
        }
    }

    /// The material on the vertical ray through `(x, y)`, sorted.
    pub(crate) fn ray(&self, x: f64, y: f64) -> Ray {
        let mut ray = Ray::new();
        match self {
            Self::Stock(StockModel::Box { lo, hi }) => {
                if x > lo.x && x < hi.x && y > lo.y && y < hi.y {
                    ray.push([lo.z, hi.z]);
                }
            }
            Self::Stock(StockModel::Cylinder { start, axis, length, radius }) => {
                ray.extend(cylinder_interval(x, y, start, axis, *length, *radius));
            }
            Self::Stock(StockModel::Grid(grid)) => {
                if let Some(top) = grid.top_at(x, y)
                    && top > grid.bottom()
                {
                    ray.push([grid.bottom(), top]);
                }
            }
            // Refused by `Solid::model`.
            Self::Stock(StockModel::Plane { .. } | StockModel::Mesh(_)) => {}
            Self::Tube { start, axis, length, outer, inner } => {
                if let Some(material) = cylinder_interval(x, y, start, axis, *length, *outer) {
                    ray.push(material);
                    if let Some(bore) = cylinder_interval(x, y, start, axis, *length, *inner) {
                        super::dexel::subtract(&mut ray, bore, &mut Vec::new());
                    }
                }
            }
        }
        ray
    }

    /// The solid on `grid`.
    pub(crate) fn field(&self, grid: Grid) -> Field {
        let mut rays = Vec::with_capacity(grid.len());
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                rays.push(self.ray(grid.x(i), grid.y(j)));
            }
        }
        Field { grid, rays }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(json: &str) -> SolidModel {
        serde_json::from_str::<Solid>(json).unwrap().model("stock").unwrap()
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
        let ray = tube.ray(0.0, 0.0);
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
            let error = serde_json::from_str::<Solid>(json).unwrap().model("part").unwrap_err();
            assert_eq!(error.field(), Some(field), "{json}");
        }
    }
}
