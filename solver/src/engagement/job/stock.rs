//! Reading the stock (docs/spec/engagement.md §2.2, §9 `E_STOCK`): a polygon with holes, several
//! polygons or a bitmap, checked for crossing and flat rings, with the earlier cuts taken out.

use super::super::outline::Outline;
use super::super::request::{Stock, StockBitmap};
use super::super::stock::{Base, Bitmap, Cut, Region, decode_base64};
use super::super::{MAX_GRID_DOTS, MAX_STOCK_VERTICES, P2};
use super::path::read_path;
use super::{point, too_large};
use crate::error::{ErrorCode, SolverError, Warning};
use crate::planar::signed_area;
use crate::validate::{MAX_COORDINATE, Measure, positive_at_most};

/// A ring of distinct points (closing repeat and consecutive duplicates removed).
fn read_ring(field: &str, points: &[[f64; 2]]) -> Result<Vec<P2>, SolverError> {
    let mut ring: Vec<P2> = Vec::with_capacity(points.len());
    for (index, p) in points.iter().enumerate() {
        let q = point(&format!("{field}[{index}]"), *p)?;
        if ring.last().is_none_or(|last| (q - last).norm() > 1e-12) {
            ring.push(q);
        }
    }
    while ring.len() > 1 && ring.first().zip(ring.last()).is_some_and(|(a, b)| (a - b).norm() <= 1e-12) {
        ring.pop();
    }
    if ring.len() < 3 {
        return Err(SolverError::new(
            ErrorCode::Stock,
            format!("a stock ring needs at least 3 distinct points (got {})", ring.len()),
        )
        .at(field));
    }
    Ok(ring)
}

/// The stock; `radius` (the tool's) sizes the index of the outline's edges.
pub(super) fn read_stock(
    stock: &Stock,
    radius: f64,
    warnings: &mut Vec<Warning>,
) -> Result<(Region, Vec<String>), SolverError> {
    let given =
        [stock.polygon.is_some(), stock.polygons.is_some(), stock.bitmap.is_some()].iter().filter(|g| **g).count();
    if given != 1 {
        return Err(SolverError::input("stock", "give exactly one of stock.polygon, stock.polygons or stock.bitmap"));
    }
    if !stock.holes.is_empty() && stock.polygon.is_none() {
        return Err(SolverError::input(
            "stock.holes",
            "holes belong to stock.polygon; with stock.polygons give each region's holes",
        ));
    }
    let base = match &stock.bitmap {
        Some(bitmap) => read_bitmap(bitmap, warnings)?,
        None => read_polygons(stock, radius)?,
    };
    let (cuts, cut_fields) = read_previous_cuts(stock, warnings)?;
    Ok((Region { base, cuts }, cut_fields))
}

/// A bitmap stock: its size against [`MAX_GRID_DOTS`], its data decoded and of the right length
/// (`W_STOCK_EMPTY` when it holds no material).
fn read_bitmap(bitmap: &StockBitmap, warnings: &mut Vec<Warning>) -> Result<Base, SolverError> {
    let origin = point("stock.bitmap.origin", bitmap.origin)?;
    let cell = positive_at_most("stock.bitmap.cell", bitmap.cell, MAX_COORDINATE, Measure::Length)?;
    if bitmap.width == 0 || bitmap.height == 0 {
        return Err(SolverError::input("stock.bitmap.width", "the bitmap needs at least one row and one column"));
    }
    let cells = u64::from(bitmap.width) * u64::from(bitmap.height);
    if cells > MAX_GRID_DOTS {
        return Err(SolverError::new(
            ErrorCode::GridMemory,
            format!("the bitmap has {cells} cells; the limit is {MAX_GRID_DOTS}"),
        )
        .at("stock.bitmap"));
    }
    let bytes = decode_base64(&bitmap.data).ok_or_else(|| {
        SolverError::new(ErrorCode::Stock, "stock.bitmap.data is not valid base64").at("stock.bitmap.data")
    })?;
    let needed = cells.div_ceil(8);
    if bytes.len() as u64 != needed {
        return Err(SolverError::new(
            ErrorCode::Stock,
            format!(
                "stock.bitmap.data holds {} bytes; {} × {} cells need {needed}",
                bytes.len(),
                bitmap.width,
                bitmap.height
            ),
        )
        .at("stock.bitmap.data"));
    }
    if bytes.iter().all(|b| *b == 0) {
        warnings.push(Warning::new("W_STOCK_EMPTY", "the bitmap holds no material"));
    }
    Ok(Base::Bitmap(Bitmap { origin, cell, width: bitmap.width as usize, height: bitmap.height as usize, bytes }))
}

/// A polygon stock (`polygon` with `holes`, or `polygons`): every ring read, the rings checked
/// for crossings (each other's and their own) and then for zero area; `radius` (the tool's)
/// sizes the index of the outline's edges.
fn read_polygons(stock: &Stock, radius: f64) -> Result<Base, SolverError> {
    let mut rings = Vec::new();
    let mut fields = Vec::new();
    let mut vertices = 0_usize;
    let mut add = |field: String, points: &[[f64; 2]]| -> Result<(), SolverError> {
        vertices += points.len();
        if vertices > MAX_STOCK_VERTICES {
            return Err(too_large("stock", "stock vertices", vertices, MAX_STOCK_VERTICES));
        }
        rings.push(read_ring(&field, points)?);
        fields.push(field);
        Ok(())
    };
    if let Some(outline) = &stock.polygon {
        add("stock.polygon".to_owned(), outline)?;
        for (index, hole) in stock.holes.iter().enumerate() {
            add(format!("stock.holes[{index}]"), hole)?;
        }
    }
    if let Some(polygons) = &stock.polygons {
        if polygons.is_empty() {
            return Err(SolverError::new(ErrorCode::Stock, "stock.polygons is empty").at("stock.polygons"));
        }
        for (index, polygon) in polygons.iter().enumerate() {
            add(format!("stock.polygons[{index}].outer"), &polygon.outer)?;
            for (hole_index, hole) in polygon.holes.iter().enumerate() {
                add(format!("stock.polygons[{index}].holes[{hole_index}]"), hole)?;
            }
        }
    }
    let outline = Outline::new(rings, radius);
    let crossing = outline.first_crossing().map_err(|_| {
        SolverError::new(
            ErrorCode::TooLarge,
            "the stock outline crowds too many edges into the same place to check it for crossings",
        )
        .at("stock")
    })?;
    if let Some(((ring_a, vertex_a), (ring_b, vertex_b))) = crossing {
        let name = |ring: usize| fields.get(ring).cloned().unwrap_or_else(|| "stock".to_owned());
        let message = if ring_a == ring_b {
            format!(
                "the stock outline crosses itself: edges from vertex {vertex_a} and vertex {vertex_b} of {} meet",
                name(ring_a)
            )
        } else {
            format!(
                "stock rings cross or touch: {}[{vertex_a}] and {}[{vertex_b}] (overlapping regions would cancel under the even-odd rule)",
                name(ring_a),
                name(ring_b)
            )
        };
        return Err(SolverError::new(ErrorCode::Stock, message).at(format!("{}[{vertex_a}]", name(ring_a))));
    }
    // After the crossing test, so a bow tie is reported as crossing, not as flat.
    for (ring, field) in outline.rings().iter().zip(&fields) {
        if signed_area(ring).abs() <= 1e-12 {
            return Err(SolverError::new(ErrorCode::Stock, "the stock ring has zero area").at(field.clone()));
        }
    }
    Ok(Base::Polygons(outline))
}

/// The earlier cuts taken out of the stock, with the field of each.
fn read_previous_cuts(stock: &Stock, warnings: &mut Vec<Warning>) -> Result<(Vec<Cut>, Vec<String>), SolverError> {
    let mut cuts = Vec::new();
    let mut cut_fields = Vec::new();
    for (index, previous) in stock.previous_cuts.iter().enumerate() {
        let field = format!("stock.previous_cuts[{index}]");
        let radius = positive_at_most(&format!("{field}.radius"), previous.radius, MAX_COORDINATE, Measure::Length)?;
        let route = read_path(&previous.path, &format!("{field}.path"), warnings)?;
        let shapes = route.pieces.iter().filter(|p| !p.rapid).map(|p| p.shape).collect();
        cuts.push(Cut::new(shapes, radius));
        cut_fields.push(field);
    }
    Ok((cuts, cut_fields))
}
