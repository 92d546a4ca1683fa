//! Prediction requests, typed: a realistic finishing program (ball end mill, zig-zag raster over
//! a curved surface) with its stock, for the invariance and split tests, the bench and the cost
//! model; a request with every option at its default; contour passes on an inclined plane.

use kerf_solver::gcode::Reference;
use kerf_solver::predict::{CuttingCoefficients, Method, PathInput, PredictRequest};
use kerf_solver::stock::Stock;
use kerf_solver::tool::{Mode, ShapeErrorPoint, Stiffness, Tool, ToolKind, ToolRef};

/// The finished surface: a smooth double wave, slopes up to about 26°.
pub fn surface(size: f64, x: f64, y: f64) -> (f64, [f64; 3]) {
    let amplitude = 25.0;
    let k = std::f64::consts::PI / size;
    let z = amplitude * (k * x).sin() * (k * y).sin();
    let dx = amplitude * k * (k * x).cos() * (k * y).sin();
    let dy = amplitude * k * (k * x).sin() * (k * y).cos();
    let length = (dx * dx + dy * dy + 1.0).sqrt();
    (z, [-dx / length, -dy / length, 1.0 / length])
}

/// A ball end mill of radius `radius` with a shape-error table and modal stiffness.
pub fn finishing_tool(radius: f64) -> Tool {
    let mut tool = Tool::new(ToolKind::Ball, radius);
    tool.shape_error = Some(
        (0..=9)
            .map(|k| {
                let angle = f64::from(k) * 10.0;
                ShapeErrorPoint { angle_deg: angle, error: 0.003 + 0.004 * angle.to_radians().sin() }
            })
            .collect(),
    );
    let mode = Mode { stiffness: 5000.0, frequency_hz: 1370.0, damping_ratio: 0.05 };
    tool.stiffness = Some(Stiffness::Modal { x: vec![mode], y: vec![mode] });
    tool
}

/// G-code of a zig-zag raster along X over `size` × `size` mm with `pick` between lines and
/// `step` between points (tip-referenced, 4 decimals as CAM posts write), and the number of feed
/// moves.
pub fn raster_program(size: f64, pick: f64, step: f64, radius: f64, feed: f64) -> (String, usize) {
    let lines = (size / pick).round() as usize + 1;
    let points = (size / step).round() as usize + 1;
    let mut text = String::with_capacity(lines * points * 32);
    text.push_str("%\nO1000 (RASTER FINISHING)\nG21 G90 G17 G40 G49 G80\nT1 M06\nS6000 M03\n");
    let tip = |x: f64, y: f64| {
        let (z, n) = surface(size, x, y);
        [x + radius * n[0], y + radius * n[1], z + radius * n[2] - radius]
    };
    let mut moves = 0;
    for line in 0..lines {
        let y = line as f64 * pick;
        for k in 0..points {
            let i = if line % 2 == 0 { k } else { points - 1 - k };
            let p = tip(i as f64 * step, y);
            if line == 0 && k == 0 {
                text.push_str(&format!("G0 X{:.4} Y{:.4} Z60.0\nG1 Z{:.4} F{feed}\n", p[0], p[1], p[2]));
            } else {
                text.push_str(&format!("X{:.4} Y{:.4} Z{:.4}\n", p[0], p[1], p[2]));
            }
            moves += 1;
        }
    }
    text.push_str("G0 Z60.0\nM05\nM30\n%\n");
    (text, moves)
}

/// The stock: the surface plus a normal allowance, as a height grid.
pub fn raster_stock(size: f64, radius: f64, allowance: f64, spacing: f64) -> Stock {
    let margin = 2.0 * radius;
    let count = ((size + 2.0 * margin) / spacing).round() as usize + 1;
    let heights = (0..count)
        .map(|j| {
            (0..count)
                .map(|i| {
                    let x = -margin + i as f64 * spacing;
                    let y = -margin + j as f64 * spacing;
                    let (z, n) = surface(size, x, y);
                    z + allowance / n[2]
                })
                .collect()
        })
        .collect();
    Stock::Grid { origin: [-margin, -margin], spacing, heights, bottom: Some(-100.0) }
}

/// A complete prediction request for the raster (ball radius 5 mm, f_t = 0.1 mm, 6000 rpm).
pub fn raster_request(
    size: f64,
    pick: f64,
    step: f64,
    method: Method,
    resolution: u32,
) -> (PredictRequest, Tool, usize) {
    let radius = 5.0;
    let tool = finishing_tool(radius);
    let (program, moves) = raster_program(size, pick, step, radius, 1200.0);
    let request = PredictRequest {
        reference: Reference::Tip,
        cutting: Some(CuttingCoefficients { ktc: 2000.0, krc: 800.0, kac: 300.0, kte: 0.0, kre: 0.0, kae: 0.0 }),
        method,
        resolution: Some(resolution),
        ..bare_request(&tool, raster_stock(size, radius, 0.2, 0.5), PathInput::Gcode { program })
    };
    (request, tool, moves)
}

/// A request with every option left to its default.
pub fn bare_request(tool: &Tool, stock: Stock, path: PathInput) -> PredictRequest {
    PredictRequest {
        tool: ToolRef::Inline(tool.clone()),
        stock,
        path,
        reference: Reference::Centre,
        spindle_rpm: None,
        spindle_direction: None,
        feed: None,
        cutting: None,
        deflection: None,
        method: Method::Sampling,
        resolution: None,
        tooth_feed_gap: None,
        view_correction: None,
        view_correction_deg: None,
        flute_zero_deg: None,
        samples_per_revolution: None,
        edge_elements: None,
        arc_tolerance: None,
        block_delete: None,
        correction: None,
        history: None,
        pass_range: None,
        exclusion_deg: None,
        exclusion_shape_error: None,
        merge_similar_passes: None,
        merge_tolerance: None,
        units: None,
        verification: None,
    }
}

/// G-code of separate straight passes of ball centres, linked by rapids 100 mm above the
/// highest pass end.
pub fn passes_program(passes: &[([f64; 3], [f64; 3])], feed: f64) -> String {
    let safe = passes.iter().map(|(a, b)| a[2].max(b[2])).fold(f64::NEG_INFINITY, f64::max) + 100.0;
    let mut text = String::from("G21 G90 G17\nS6000 M03\n");
    for (start, end) in passes {
        text.push_str(&format!(
            "G0 X{:.9} Y{:.9} Z{safe:.9}\nG0 Z{:.9}\nG1 X{:.9} Y{:.9} Z{:.9} F{feed}\nG0 Z{safe:.9}\n",
            start[0], start[1], start[2], end[0], end[1], end[2]
        ));
    }
    text.push_str("M30\n");
    text
}

/// Ball radius, pick feed and tooth feed of a test case, mm.
#[derive(Debug, Clone, Copy)]
pub struct Conditions {
    pub radius: f64,
    pub pick: f64,
    pub tooth_feed: f64,
}

/// Case B's conditions: R = 5, pick 0.5, f_t = 0.1.
pub const FINE: Conditions = Conditions { radius: 5.0, pick: 0.5, tooth_feed: 0.1 };

/// The patent's Fig. 16 conditions (case C): R = 10, pick 0.63, f_t = 0.4.
pub const PATENT: Conditions = Conditions { radius: 10.0, pick: 0.63, tooth_feed: 0.4 };

/// Contour passes (11 passes of 30 mm + 6R) on a plane rising at `slope_deg` toward azimuth
/// `uphill_deg`, the whole case turned by `turn_deg` about Z and moved by `shift`; the stock is
/// the plane plus 0.2 mm. Returns the request (force model, isotropic modal stiffness, 6000 rpm,
/// 2 flutes) and the tool; pass 5 is the middle one.
pub fn inclined_case(
    slope_deg: f64,
    uphill_deg: f64,
    turn_deg: f64,
    shift: [f64; 3],
    method: Method,
) -> (PredictRequest, Tool) {
    inclined_case_with(FINE, slope_deg, uphill_deg, turn_deg, shift, method)
}

/// [`inclined_case`] under other conditions.
pub fn inclined_case_with(
    conditions: Conditions,
    slope_deg: f64,
    uphill_deg: f64,
    turn_deg: f64,
    shift: [f64; 3],
    method: Method,
) -> (PredictRequest, Tool) {
    let radius = conditions.radius;
    let half = 15.0 + 3.0 * radius;
    let tool = finishing_tool(radius);
    let (s, c) = slope_deg.to_radians().sin_cos();
    let (sa, ca) = (uphill_deg + turn_deg).to_radians().sin_cos();
    let normal = [-s * ca, -s * sa, c];
    let uphill = [c * ca, c * sa, s];
    let feed = [-sa, ca, 0.0];
    let at = |k: f64, along: f64, lift: f64| {
        let mut p = [0.0; 3];
        for i in 0..3 {
            p[i] = k * conditions.pick * uphill[i] + lift * normal[i] + along * feed[i] + shift[i];
        }
        p
    };
    let passes: Vec<([f64; 3], [f64; 3])> =
        (-5..=5).map(|k| (at(f64::from(k), -half, radius), at(f64::from(k), half, radius))).collect();
    let point = at(0.0, 0.0, 0.2);
    let stock = Stock::Plane {
        point,
        normal,
        min: [shift[0] - 1000.0, shift[1] - 1000.0],
        max: [shift[0] + 1000.0, shift[1] + 1000.0],
    };
    let mut request = bare_request(
        &tool,
        stock,
        PathInput::Gcode { program: passes_program(&passes, conditions.tooth_feed * 6000.0 * 2.0) },
    );
    request.cutting = Some(CuttingCoefficients { ktc: 2000.0, krc: 800.0, kac: 300.0, kte: 0.0, kre: 0.0, kae: 0.0 });
    request.method = method;
    request.pass_range = Some([5, 6]);
    (request, tool)
}
