//! kerf's own deburr program cut by the verify simulation: the chamfer band it leaves against the
//! width W the deburr spec promises (docs/spec/verify.md §7, docs/spec/deburr.md §5.2). A
//! crate-root test, as it drives both the deburr and verify modules.

use serde_json::json;

use crate::capability::Run;
use crate::tool::ToolRef;
use crate::verify::Found;
use crate::verify::tests::{request, tools};

/// The chamfer kerf's deburr program cuts on reference case 1 (docs/spec/deburr.md §5.2: tube
/// R 50 (bore 40) along y, hole R 10 along z, ball R 3, Q 0.5, so W = 0.7071), with `method`:
/// per angle φ of 0°, 90°, 180° and 270° (where the ridge's normal plane is the vertical plane
/// through the hole axis) the band's edges G1 on the tube and G2 on the hole wall as the dexels
/// show them, the distance |G1 G2|, and the outermost reach of any removal.
struct Band {
    widths: Vec<f64>,
    summary: crate::deburr::DeburrSummary,
    /// The largest radius from the hole axis of a ray that lost material, and the largest band
    /// edge radius measured.
    reach: (f64, f64),
    /// Material removed from the tube's lower wall, mm³.
    lower_removed: f64,
}

fn deburr_band(method: &str, spacing: f64) -> Band {
    // The program is cut with the tool's tip programmed, as verify reads it.
    let (outer, hole) = (50.0_f64, 10.0_f64);
    let deburr: crate::deburr::DeburrRequest = serde_json::from_value(json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": outer},
        "hole": {"shape": "round", "radius": hole}, "edge": "outer", "cut_amount": 0.5, "tolerance": 0.01,
        "method": method,
    }))
    .unwrap();
    let ToolRef::Inline(tool) = &deburr.tool else { unreachable!("an inline tool") };
    let answer = crate::deburr::solve(&deburr, tool).unwrap();
    let post = crate::gcode::Post {
        dialect: crate::gcode::Dialect::Fanuc,
        reference: crate::gcode::Reference::Tip,
        tool: crate::gcode::ToolCall::Table(7),
        arcs: crate::gcode::Arcs::Chords,
        plunge_feed: None,
        units: crate::units::Units::Mm,
    };
    let program = crate::deburr::program(&answer, &post).unwrap();
    let body = json!({
        "program": program,
        "tools": [{"kind": "ball", "radius": 3}],
        "stock": {"kind": "tube", "start": [0, -16, 0], "end": [0, 16, 0], "outer_radius": outer, "inner_radius": 40,
                  "holes": [{"start": [0, 0, -60], "end": [0, 0, 60], "radius": hole}]},
        "resolution": spacing,
    });
    let request = request(body);
    let job = request.validate(&tools(&request), Found::default(), None, Default::default()).unwrap();
    let (cut, stock) = crate::verify::simulate::cut_stock(&job, &Run::default()).unwrap();
    assert!(cut.ok, "{:?}", cut.findings);
    let original = job.stock.field(job.grid);
    let grid = job.grid;
    // The top of the upper wall on each ray before and after, and what the lower wall lost.
    let mut rays = Vec::new();
    let mut lower_removed = 0.0;
    let mut reach = 0.0_f64;
    for (index, (before, after)) in original.rays.iter().zip(&stock.rays).enumerate() {
        let (x, y) = (grid.x(index % grid.nx), grid.y(index / grid.nx));
        let lower = |ray: &crate::verify::dexel::Ray| {
            ray.iter().filter(|piece| piece[1] <= 0.0).map(|p| p[1] - p[0]).sum::<f64>()
        };
        lower_removed += (lower(before) - lower(after)) * grid.cell_area();
        let (Some(top_before), Some(top_after)) = (before.last(), after.last()) else { continue };
        if top_before[1] - top_after[1] > 1e-9 {
            reach = reach.max(x.hypot(y));
            rays.push((x, y, top_after[1], top_before[1]));
        }
    }
    let mut widths = Vec::new();
    let mut edge = 0.0_f64;
    for phi in [0.0_f64, 90.0, 180.0, 270.0] {
        let (c, s) = (phi.to_radians().cos(), phi.to_radians().sin());
        // The rays on the radial line at φ (within half a spacing of it, on one side), outward.
        let mut line: Vec<(f64, f64, f64)> = rays
            .iter()
            .filter(|(x, y, ..)| {
                let across = -s * x + c * y;
                (0.0..spacing).contains(&across) && c * x + s * y > 0.0
            })
            .map(|&(x, y, after, before)| (x.hypot(y), after, before - after))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(line.len() >= 4, "φ {phi}: {line:?}");
        // G1: where the depth removed, extrapolated along the two outermost rays, reaches 0, on
        // the tube (z = √(R² − x²)); G2: the chamfer's floor extrapolated along the two innermost
        // rays to the hole wall.
        let [.., (r_a, _, d_a), (r_b, _, d_b)] = line[..] else { unreachable!() };
        let r1 = r_b + d_b * (r_b - r_a) / (d_a - d_b);
        let x1 = r1 * c;
        let z1 = (outer * outer - x1 * x1).sqrt();
        let [(r_c, z_c, _), (r_d, z_d, _), ..] = line[..] else { unreachable!() };
        let z2 = z_c + (z_d - z_c) * (hole - r_c) / (r_d - r_c);
        widths.push((r1 - hole).hypot(z1 - z2));
        edge = edge.max(r1);
    }
    Band { widths, summary: answer.summary, reach: (reach, edge), lower_removed }
}

#[test]
fn the_deburr_program_cuts_its_chamfer_band_w_wide_and_nothing_beyond() {
    // The exact method promises a swept width within W ± max(0.005, TA) = ± 0.01 mm here; the
    // dexels measure it within that at 0.1 mm and 0.05 mm spacing (figures in the commit), and no
    // ray beyond the band's outer edge (by more than a spacing) nor the tube's lower wall loses
    // material.
    for spacing in [0.1, 0.05] {
        let band = deburr_band("exact", spacing);
        let w = band.summary.width;
        let promise = 0.005_f64.max(band.summary.tolerance);
        eprintln!(
            "exact at {spacing}: W {w}, measured {:?}, swept {}–{}, reach {:?}",
            band.widths, band.summary.swept_width_min, band.summary.swept_width_max, band.reach
        );
        for width in &band.widths {
            assert!((width - w).abs() <= promise, "spacing {spacing}: {:?} against W = {w}", band.widths);
        }
        assert!(band.reach.0 <= band.reach.1 + spacing, "spacing {spacing}: removal out to {:?}", band.reach);
        assert!(band.reach.1 < 10.0 + w, "{:?}", band.reach);
        assert_eq!(band.lower_removed, 0.0);
    }
}
