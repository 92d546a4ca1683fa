//! A stock as a solid, shared by prediction (the stock W before the analysed operation,
//! docs/spec/predict.md §1.2 I1, §3.5) and verification (docs/spec/verify.md): analytic solids
//! (box, half-space under a plane, cylinder), a height grid, or a closed STL mesh; point
//! membership, a conservative classification of boxes used to skip whole tiles of samples, and a
//! bound of the top under the ball that narrows the motion a scene gathers.

pub mod stl;
mod units;

use crate::error::ErrorCode;
use serde::{Deserialize, Serialize};

use crate::error::SolverError;
use crate::geometry::{Vec3, vec3};
use crate::validate::{Measure, coordinate, coordinates, positive};
use stl::Mesh;

/// Most nodes of a height grid.
pub const MAX_GRID_NODES: usize = 4_000_000;
/// Side of the min/max blocks of a height grid, in nodes.
const BLOCK: usize = 8;
/// Most nodes a box classification reads one by one (more: the blocks' extremes).
const MAX_RANGE_NODES: usize = 25;
/// Most nodes [`StockModel::highest_top`] reads one by one: a ball's footprint at the usual grid
/// spacings (blocks reach up to 8 nodes beyond it, a far looser bound on a slope).
const MAX_TOP_NODES: usize = 4096;

/// The stock as the client describes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Stock {
    /// An axis-aligned box.
    Box {
        /// Lowest corner, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        min: [f64; 3],
        /// Highest corner, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        max: [f64; 3],
    },
    /// The material below a plane, limited to an xy footprint rectangle (e.g. a semi-finished
    /// face with its allowance).
    Plane {
        /// A point of the plane, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        point: [f64; 3],
        /// Normal pointing out of the material (needs a positive z component).
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        normal: [f64; 3],
        /// Footprint's lowest x and y, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        min: [f64; 2],
        /// Footprint's highest x and y, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        max: [f64; 2],
    },
    /// A solid cylinder between two points of its axis.
    Cylinder {
        /// One end of the axis, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        start: [f64; 3],
        /// The other end of the axis, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        end: [f64; 3],
        /// Radius, mm.
        radius: f64,
    },
    /// A height field (Z-map): the top of the material at grid nodes, bilinear in between.
    Grid {
        /// xy of node `heights[0][0]`, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        origin: [f64; 2],
        /// Node spacing in x and y, mm.
        spacing: f64,
        /// Top heights, one row per y (`heights[j][i]` at x = origin.x + i·spacing, y = origin.y +
        /// j·spacing); at least 2 × 2 nodes, at most 4 000 000.
        heights: Vec<Vec<f64>>,
        /// Bottom of the material, mm (default: unbounded below).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        bottom: Option<f64>,
    },
    /// A closed triangle mesh (ASCII or binary STL) uploaded with the request: the solver entry
    /// takes its bytes separately.
    Mesh {
        /// The units of the file's coordinates (an STL file names none): default the request's
        /// `units`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        units: Option<crate::units::Units>,
    },
}

/// Where a box lies relative to the stock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Region {
    Outside,
    Inside,
    Mixed,
}

/// A validated stock, ready for queries.
#[derive(Debug, Clone)]
pub(crate) enum StockModel {
    Box { lo: Vec3, hi: Vec3 },
    Plane { point: Vec3, normal: Vec3, lo: [f64; 2], hi: [f64; 2] },
    Cylinder { start: Vec3, axis: Vec3, length: f64, radius: f64 },
    Grid(HeightGrid),
    Mesh(Box<Mesh>),
}

/// A height grid with per-block extremes.
#[derive(Debug, Clone)]
pub(crate) struct HeightGrid {
    origin: [f64; 2],
    spacing: f64,
    nx: usize,
    ny: usize,
    heights: Vec<f64>,
    bottom: f64,
    blocks_x: usize,
    block_min: Vec<f64>,
    block_max: Vec<f64>,
}

impl HeightGrid {
    fn new(origin: [f64; 2], spacing: f64, rows: &[Vec<f64>], bottom: f64) -> Self {
        let ny = rows.len();
        let nx = rows.first().map_or(0, Vec::len);
        let heights: Vec<f64> = rows.iter().flatten().copied().collect();
        let blocks_x = nx.div_ceil(BLOCK);
        let blocks_y = ny.div_ceil(BLOCK);
        let mut block_min = vec![f64::INFINITY; blocks_x * blocks_y];
        let mut block_max = vec![f64::NEG_INFINITY; blocks_x * blocks_y];
        for j in 0..ny {
            for i in 0..nx {
                let h = heights[j * nx + i];
                let b = (j / BLOCK) * blocks_x + i / BLOCK;
                block_min[b] = block_min[b].min(h);
                block_max[b] = block_max[b].max(h);
            }
        }
        Self { origin, spacing, nx, ny, heights, bottom, blocks_x, block_min, block_max }
    }

    fn extent(&self) -> ([f64; 2], [f64; 2]) {
        (
            self.origin,
            [
                self.origin[0] + (self.nx - 1) as f64 * self.spacing,
                self.origin[1] + (self.ny - 1) as f64 * self.spacing,
            ],
        )
    }

    /// [`Self::top`] for the other modules.
    pub(crate) fn top_at(&self, x: f64, y: f64) -> Option<f64> {
        self.top(x, y)
    }

    /// Bottom of the material.
    pub(crate) fn bottom(&self) -> f64 {
        self.bottom
    }

    /// Bilinear top height at (x, y), `None` outside the footprint.
    fn top(&self, x: f64, y: f64) -> Option<f64> {
        let u = (x - self.origin[0]) / self.spacing;
        let v = (y - self.origin[1]) / self.spacing;
        let (max_u, max_v) = ((self.nx - 1) as f64, (self.ny - 1) as f64);
        if !(0.0..=max_u).contains(&u) || !(0.0..=max_v).contains(&v) {
            return None;
        }
        // 0 ≤ u, v < 2³² here, so truncation is the floor (without a libm call on baseline
        // x86-64), and a cast through u32 needs fewer instructions than one to usize.
        let i = (u as u32 as usize).min(self.nx - 2);
        let j = (v as u32 as usize).min(self.ny - 2);
        let (fu, fv) = (u - i as f64, v - j as f64);
        let corner = j * self.nx + i;
        let (row, next_row) =
            (&self.heights[corner..corner + 2], &self.heights[corner + self.nx..corner + self.nx + 2]);
        Some((1.0 - fv) * ((1.0 - fu) * row[0] + fu * row[1]) + fv * ((1.0 - fu) * next_row[0] + fu * next_row[1]))
    }

    /// Lowest and highest node heights that bound the surface over the rectangle: the nodes of
    /// the cells it meets when they are few (a tile of samples or pixels spans a handful), the
    /// per-block extremes otherwise.
    fn range(&self, lo: [f64; 2], hi: [f64; 2], max_nodes: usize) -> (f64, f64) {
        let index = |v: f64, origin: f64, count: usize| ((v - origin) / self.spacing).clamp(0.0, (count - 1) as f64);
        // The indices are ≥ 0 (and < 2³²), so truncation is the floor and one more where it cut a
        // fraction is the ceiling (without libm calls on baseline x86-64).
        let floor = |u: f64| u as u32 as usize;
        let ceil = |u: f64| floor(u) + usize::from((floor(u) as f64) < u);
        let i0 = floor(index(lo[0], self.origin[0], self.nx));
        let i1 = ceil(index(hi[0], self.origin[0], self.nx));
        let j0 = floor(index(lo[1], self.origin[1], self.ny));
        let j1 = ceil(index(hi[1], self.origin[1], self.ny));
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        if (i1 - i0 + 1) * (j1 - j0 + 1) <= max_nodes {
            for j in j0..=j1 {
                for &h in &self.heights[j * self.nx + i0..=j * self.nx + i1] {
                    low = low.min(h);
                    high = high.max(h);
                }
            }
        } else {
            for bj in j0 / BLOCK..=j1 / BLOCK {
                for bi in i0 / BLOCK..=i1 / BLOCK {
                    let b = bj * self.blocks_x + bi;
                    low = low.min(self.block_min[b]);
                    high = high.max(self.block_max[b]);
                }
            }
        }
        // The bilinear value can round a few units in the last place beyond its nodes.
        let slack = 8.0 * f64::EPSILON * low.abs().max(high.abs());
        (low - slack, high + slack)
    }
}

fn stock_error(field: &str, message: impl Into<String>) -> SolverError {
    SolverError::input(field, message)
}

impl Stock {
    /// Validates the description and builds the model; `mesh` holds the STL bytes for `mesh`.
    pub(crate) fn model(&self, mesh: Option<&[u8]>) -> Result<StockModel, SolverError> {
        let point = |name: &str, p: [f64; 3]| -> Result<Vec3, SolverError> {
            Ok(vec3(coordinates(&format!("stock.{name}"), p)?))
        };
        match self {
            Self::Box { min, max } => {
                let (lo, hi) = (point("min", *min)?, point("max", *max)?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err(stock_error("stock.max", "stock.max must exceed stock.min on every axis"));
                }
                Ok(StockModel::Box { lo, hi })
            }
            Self::Plane { point: p, normal, min, max } => {
                let p = point("point", *p)?;
                let n = point("normal", *normal)?;
                let length = n.norm();
                if length == 0.0 || n.z / length <= 1e-9 {
                    return Err(stock_error(
                        "stock.normal",
                        "the plane's outward normal must point upward (positive z)",
                    ));
                }
                for k in 0..2 {
                    coordinate(&format!("stock.min[{k}]"), min[k])?;
                    coordinate(&format!("stock.max[{k}]"), max[k])?;
                    if max[k] <= min[k] {
                        return Err(stock_error("stock.max", "the footprint's max must exceed its min in x and y"));
                    }
                }
                Ok(StockModel::Plane { point: p, normal: n / length, lo: *min, hi: *max })
            }
            Self::Cylinder { start, end, radius } => {
                let (a, b) = (point("start", *start)?, point("end", *end)?);
                let radius = coordinate("stock.radius", positive("stock.radius", *radius, Measure::Length)?)?;
                let length = (b - a).norm();
                if length == 0.0 {
                    return Err(stock_error("stock.end", "the cylinder's end equals its start"));
                }
                Ok(StockModel::Cylinder { start: a, axis: (b - a) / length, length, radius })
            }
            Self::Grid { origin, spacing, heights, bottom } => {
                coordinates("stock.origin", *origin)?;
                let spacing = coordinate("stock.spacing", positive("stock.spacing", *spacing, Measure::Length)?)?;
                let ny = heights.len();
                let nx = heights.first().map_or(0, Vec::len);
                if nx < 2 || ny < 2 {
                    return Err(stock_error("stock.heights", "a height grid needs at least 2 × 2 nodes"));
                }
                if nx.saturating_mul(ny) > MAX_GRID_NODES {
                    return Err(SolverError::new(
                        ErrorCode::GridTooLarge,
                        format!("the height grid has {nx} × {ny} nodes; the limit is {MAX_GRID_NODES}"),
                    )
                    .at("stock.heights"));
                }
                for (j, row) in heights.iter().enumerate() {
                    if row.len() != nx {
                        return Err(stock_error(
                            format!("stock.heights[{j}]").as_str(),
                            format!("every row needs {nx} heights (row {j} has {})", row.len()),
                        ));
                    }
                    for (i, h) in row.iter().enumerate() {
                        coordinate(&format!("stock.heights[{j}][{i}]"), *h)?;
                    }
                }
                let bottom = match bottom {
                    Some(b) => coordinate("stock.bottom", *b)?,
                    None => f64::NEG_INFINITY,
                };
                Ok(StockModel::Grid(HeightGrid::new(*origin, spacing, heights, bottom)))
            }
            Self::Mesh { units } => {
                let Some(bytes) = mesh else {
                    return Err(stock_error("stock", "a mesh stock needs its STL file uploaded with the request"));
                };
                let triangles = stl::parse_in(bytes, units.unwrap_or_default())?;
                stl::check_closed(&triangles)?;
                Ok(StockModel::Mesh(Box::new(Mesh::new(&triangles))))
            }
        }
    }
}

impl StockModel {
    /// Whether `q` lies in the material, more than `margin` below its top skin (the exit of a
    /// ray from below, §3.5) and inside its footprint.
    pub(crate) fn contains(&self, q: &Vec3, margin: f64) -> bool {
        match self {
            Self::Box { lo, hi } => {
                q.x > lo.x && q.x < hi.x && q.y > lo.y && q.y < hi.y && q.z > lo.z && q.z < hi.z - margin
            }
            Self::Plane { point, normal, lo, hi } => {
                q.x > lo[0] && q.x < hi[0] && q.y > lo[1] && q.y < hi[1] && (q - point).dot(normal) < -margin * normal.z
            }
            Self::Cylinder { start, axis, length, radius } => {
                let d = q - start;
                let t = d.dot(axis);
                t > 0.0 && t < *length && (d - t * axis).norm() < radius - margin
            }
            Self::Grid(grid) => grid.top(q.x, q.y).is_some_and(|top| q.z < top - margin && q.z > grid.bottom),
            Self::Mesh(mesh) => mesh.contains(q, margin),
        }
    }

    /// Conservative position of the box `[lo, hi]`: `Inside` or `Outside` only when every point
    /// of the box is.
    pub(crate) fn classify(&self, lo: &Vec3, hi: &Vec3, margin: f64) -> Region {
        match self {
            Self::Box { lo: a, hi: b } => {
                if hi.x <= a.x || lo.x >= b.x || hi.y <= a.y || lo.y >= b.y || hi.z <= a.z || lo.z >= b.z - margin {
                    Region::Outside
                } else if lo.x > a.x && hi.x < b.x && lo.y > a.y && hi.y < b.y && lo.z > a.z && hi.z < b.z - margin {
                    Region::Inside
                } else {
                    Region::Mixed
                }
            }
            Self::Plane { point, normal, lo: a, hi: b } => {
                if hi.x <= a[0] || lo.x >= b[0] || hi.y <= a[1] || lo.y >= b[1] {
                    return Region::Outside;
                }
                let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
                for corner in 0..8 {
                    let c = Vec3::new(
                        if corner & 1 == 0 { lo.x } else { hi.x },
                        if corner & 2 == 0 { lo.y } else { hi.y },
                        if corner & 4 == 0 { lo.z } else { hi.z },
                    );
                    let s = (c - point).dot(normal) + margin * normal.z;
                    low = low.min(s);
                    high = high.max(s);
                }
                let footprint_inside = lo.x > a[0] && hi.x < b[0] && lo.y > a[1] && hi.y < b[1];
                if low >= 0.0 {
                    Region::Outside
                } else if high < 0.0 && footprint_inside {
                    Region::Inside
                } else {
                    Region::Mixed
                }
            }
            Self::Cylinder { start, axis, length, radius } => {
                let centre = 0.5 * (lo + hi);
                let half = 0.5 * (hi - lo).norm();
                let d = centre - start;
                let t = d.dot(axis);
                let to_line = (d - t * axis).norm();
                let to_segment = crate::geometry::distance_to_segment(&centre, start, &(start + *length * axis));
                if to_segment - half >= *radius {
                    Region::Outside
                } else if to_line + half < radius - margin && t - half > 0.0 && t + half < *length {
                    Region::Inside
                } else {
                    Region::Mixed
                }
            }
            Self::Grid(grid) => {
                let (a, b) = grid.extent();
                if hi.x < a[0] || lo.x > b[0] || hi.y < a[1] || lo.y > b[1] || hi.z <= grid.bottom {
                    return Region::Outside;
                }
                let (low, high) = grid.range([lo.x, lo.y], [hi.x, hi.y], MAX_RANGE_NODES);
                let footprint_inside = lo.x > a[0] && hi.x < b[0] && lo.y > a[1] && hi.y < b[1];
                if lo.z >= high - margin {
                    Region::Outside
                } else if hi.z < low - margin && lo.z > grid.bottom && footprint_inside {
                    Region::Inside
                } else {
                    Region::Mixed
                }
            }
            Self::Mesh(mesh) => {
                if mesh.touches(&(lo - Vec3::repeat(margin)), &(hi + Vec3::repeat(margin))) {
                    Region::Mixed
                } else if mesh.contains(&(0.5 * (lo + hi)), 0.0) {
                    Region::Inside
                } else {
                    Region::Outside
                }
            }
        }
    }

    /// An upper bound of the z of the material over the xy rectangle `[lo, hi]` (∞ where no
    /// cheap one is known: the solids other than a box or a height grid).
    pub(crate) fn highest_top(&self, lo: [f64; 2], hi: [f64; 2]) -> f64 {
        match self {
            Self::Box { hi: top, .. } => top.z,
            Self::Grid(grid) => grid.range(lo, hi, MAX_TOP_NODES).1,
            Self::Plane { .. } | Self::Cylinder { .. } | Self::Mesh(_) => f64::INFINITY,
        }
    }

    /// The xy bounding rectangle of the material.
    pub(crate) fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::Box { lo, hi } => ([lo.x, lo.y], [hi.x, hi.y]),
            Self::Plane { lo, hi, .. } => (*lo, *hi),
            Self::Cylinder { start, axis, length, radius } => {
                let end = start + *length * axis;
                let reach = |k: usize| radius * (1.0 - axis[k] * axis[k]).max(0.0).sqrt();
                (
                    [start.x.min(end.x) - reach(0), start.y.min(end.y) - reach(1)],
                    [start.x.max(end.x) + reach(0), start.y.max(end.y) + reach(1)],
                )
            }
            Self::Grid(grid) => grid.extent(),
            Self::Mesh(mesh) => ([mesh.lo.x, mesh.lo.y], [mesh.hi.x, mesh.hi.y]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn models() -> Vec<StockModel> {
        let heights: Vec<Vec<f64>> =
            (0..21).map(|j| (0..31).map(|i| 0.1 * f64::from(i) - 0.05 * f64::from(j)).collect()).collect();
        let triangles = super::stl::tests::box_triangles(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(2.0, 1.0, 0.5));
        vec![
            Stock::Box { min: [-1.0, -2.0, -3.0], max: [2.0, 1.0, 0.5] }.model(None).unwrap(),
            Stock::Plane { point: [0.0, 0.0, 0.2], normal: [-0.3, 0.2, 1.0], min: [-2.0, -2.0], max: [2.0, 2.0] }
                .model(None)
                .unwrap(),
            Stock::Cylinder { start: [0.0, -2.0, 0.0], end: [0.0, 2.0, 0.0], radius: 1.5 }.model(None).unwrap(),
            Stock::Grid { origin: [-1.5, -1.0], spacing: 0.1, heights, bottom: Some(-2.0) }.model(None).unwrap(),
            Stock::Mesh { units: None }.model(Some(&super::stl::tests::binary_stl(&triangles))).unwrap(),
        ]
    }

    #[test]
    fn classification_never_contradicts_membership() {
        for (index, model) in models().iter().enumerate() {
            let mut seen = [0usize; 3];
            for i in 0..14 {
                for j in 0..14 {
                    for k in 0..10 {
                        let lo = Vec3::new(
                            -2.6 + 0.37 * f64::from(i),
                            -2.6 + 0.37 * f64::from(j),
                            -3.5 + 0.45 * f64::from(k),
                        );
                        let hi = lo + Vec3::new(0.3, 0.2, 0.25);
                        let region = model.classify(&lo, &hi, 1e-9);
                        seen[region as usize] += 1;
                        if region == Region::Mixed {
                            continue;
                        }
                        for s in 0..4 {
                            for t in 0..4 {
                                for u in 0..4 {
                                    let q = lo
                                        + Vec3::new(
                                            0.1 * f64::from(s),
                                            0.2 / 3.0 * f64::from(t),
                                            0.25 / 3.0 * f64::from(u),
                                        );
                                    assert_eq!(
                                        model.contains(&q, 1e-9),
                                        region == Region::Inside,
                                        "model {index} at {q:?}"
                                    );
                                }
                            }
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&n| n > 0), "model {index}: {seen:?}");
        }
    }

    #[test]
    fn bad_stocks_name_their_field() {
        let bad = [
            (Stock::Box { min: [0.0, 0.0, 0.0], max: [1.0, 1.0, 0.0] }, "stock.max"),
            (
                Stock::Plane { point: [0.0; 3], normal: [0.0, 0.0, -1.0], min: [0.0, 0.0], max: [1.0, 1.0] },
                "stock.normal",
            ),
            (Stock::Cylinder { start: [0.0; 3], end: [0.0, 1.0, 0.0], radius: f64::NAN }, "stock.radius"),
            (
                Stock::Grid {
                    origin: [0.0, 0.0],
                    spacing: 1.0,
                    heights: vec![vec![0.0, 0.0], vec![0.0]],
                    bottom: None,
                },
                "stock.heights[1]",
            ),
            (Stock::Mesh { units: None }, "stock"),
        ];
        for (stock, field) in bad {
            assert_eq!(stock.model(None).unwrap_err().field(), Some(field));
        }
    }
}
