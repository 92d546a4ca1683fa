//! The simulation against analytic removals and deliberate faults (docs/spec/verify.md §7 Tests).

use std::f64::consts::PI;

use proptest::prelude::*;
use serde_json::{Value, json};

use super::{Cut, FindingKind, Found, Meshes, VerifyRequest, verify};
use crate::capability::Run;
use crate::error::ErrorCode;
use crate::geometry::Vec3;
use crate::stock::stl::tests::{binary_stl, box_triangles};
use crate::tool::{Tool, ToolRef};

pub(crate) fn request(body: Value) -> VerifyRequest {
    serde_json::from_value(body).expect("a valid request")
}

/// The tools of `request` as resolution gives them (inline only here).
pub(crate) fn tools(request: &VerifyRequest) -> Vec<Tool> {
    request
        .tools
        .iter()
        .map(|tool| match tool {
            ToolRef::Inline(tool) => tool.clone(),
            ToolRef::Number(_) => panic!("inline tools only"),
        })
        .collect()
}

fn run(body: Value) -> Cut {
    let request = request(body);
    verify(&request, &tools(&request), Found::default(), &Run::default()).expect("verified")
}

fn slot(resolution: Option<f64>) -> Value {
    let mut body = json!({
        "program": "G21 G90\nG0 X0 Y0 Z5\nG1 Z-2 F300\nG1 X50 F600\nG0 Z5\nM30",
        "tools": [{"kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [-20, -20, -10], "max": [70, 20, 0]},
    });
    if let Some(resolution) = resolution {
        body["resolution"] = json!(resolution);
    }
    body
}

#[test]
fn a_flat_slot_removes_its_exact_volume_and_converges() {
    let exact = 2.0 * (10.0 * 50.0 + PI * 25.0);
    let default = run(slot(None));
    assert_eq!(default.resolution, 0.25);
    let error = |cut: &Cut| (cut.removed_volume_mm3 / exact - 1.0).abs();
    assert!(error(&default) < 0.005, "{} against {exact}", default.removed_volume_mm3);
    let errors: Vec<f64> = [1.0, 0.5, 0.1, 0.05].iter().map(|&h| error(&run(slot(Some(h))))).collect();
    assert!(errors[3] < errors[0] && errors[3] < 0.001, "{errors:?}");
    assert!((default.stock_volume_mm3 - 90.0 * 40.0 * 10.0).abs() < 1e-6);
    assert!((default.final_volume_mm3 + default.removed_volume_mm3 - default.stock_volume_mm3).abs() < 1e-6);
    let blocks: Vec<usize> = default.blocks.iter().map(|block| block.line).collect();
    assert_eq!(blocks, [3, 4]);
    let along = &default.blocks[1];
    assert_eq!(along.time_s, Some(5.0));
    assert!((along.removal_rate_mm3_per_min.unwrap() - along.removed_mm3 * 12.0).abs() < 1e-9);
    assert!(default.ok, "{:?}", default.findings);
}

#[test]
fn a_ball_groove_has_the_circular_segment_as_its_cross_section() {
    // Ball R3, 1 deep, 40 long between centres: the circular segment along the groove plus one
    // spherical cap (its two halves at the ends).
    let (radius, depth, length): (f64, f64, f64) = (3.0, 1.0, 40.0);
    let segment = radius * radius * ((radius - depth) / radius).acos()
        - (radius - depth) * (2.0 * radius * depth - depth * depth).sqrt();
    let cap = PI * depth * depth * (3.0 * radius - depth) / 3.0;
    let cut = run(json!({
        "program": "G0 X0 Y0 Z1\nG1 Z-1 F200\nG1 X40\nG0 Z5",
        "tools": [{"kind": "ball", "radius": 3}],
        "stock": {"kind": "box", "min": [-10, -10, -5], "max": [50, 10, 0]},
        "resolution": 0.02,
    }));
    let exact = segment * length + cap;
    assert!((cut.removed_volume_mm3 / exact - 1.0).abs() < 0.002, "{} against {exact}", cut.removed_volume_mm3);
    // The plunge takes the whole cap; the move along then adds the segment times its length (its
    // end's half cap, less the half of the plunge's cap it passes through).
    let plunge = cut.blocks.iter().find(|block| block.line == 2).unwrap();
    assert!((plunge.removed_mm3 / cap - 1.0).abs() < 0.003, "{} against {cap}", plunge.removed_mm3);
    let middle = cut.blocks.iter().find(|block| block.line == 3).unwrap();
    let expected = segment * length;
    assert!((middle.removed_mm3 / expected - 1.0).abs() < 0.003, "{} against {expected}", middle.removed_mm3);
}

#[test]
fn a_helical_ramp_and_its_clean_up_circle_remove_the_annulus() {
    // A flat Ø10 on a circle of radius 10 ramps down two turns to z = −2, then a full circle at
    // the bottom: the annulus 5 < r < 15, 2 deep.
    let cut = run(json!({
        "program": "G0 X10 Y0 Z1\nG1 Z0 F300\nG3 X10 Y0 Z-1 I-10 J0\nG3 X10 Y0 Z-2 I-10 J0\nG3 X10 Y0 I-10 J0\nG0 Z5",
        "tools": [{"kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [-20, -20, -10], "max": [20, 20, 0]},
        "resolution": 0.1,
    }));
    let exact = PI * (15.0 * 15.0 - 5.0 * 5.0) * 2.0;
    assert!((cut.removed_volume_mm3 / exact - 1.0).abs() < 0.003, "{} against {exact}", cut.removed_volume_mm3);
    // The first turn of the ramp takes less than the 1 mm layer it ends at (it starts at the top)
    // and more than half of it.
    let first = cut.blocks.iter().find(|block| block.line == 3).unwrap();
    assert!(first.removed_mm3 < exact / 2.0 && first.removed_mm3 > exact / 4.0, "{}", first.removed_mm3);
}

fn kinds(cut: &Cut) -> Vec<(FindingKind, Option<usize>)> {
    cut.findings.iter().map(|finding| (finding.kind, finding.line)).collect()
}

#[test]
fn a_dip_into_the_part_is_a_gouge_at_its_line() {
    // A face pass over a part whose top is at z = −1, dipping 0.2 mm into it on line 5.
    let cut = run(json!({
        "program": "G0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X10\nG1 X12 Z-1.2\nG1 X14 Z-1\nG1 X30\nG0 Z5",
        "tools": [{"kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [-5, -4, -10], "max": [25, 4, 0]},
        "part": {"kind": "box", "min": [-5, -4, -10], "max": [25, 4, -1]},
    }));
    // Line 5 climbs back out and still takes 0.1 mm at the far side of the tool.
    let gouges: Vec<_> = cut.findings.iter().filter(|finding| finding.kind == FindingKind::Gouge).collect();
    assert_eq!(gouges.iter().map(|gouge| gouge.line).collect::<Vec<_>>(), [Some(4), Some(5)], "{:?}", cut.findings);
    assert!((gouges[0].depth - 0.2).abs() < 1e-9, "{:?}", gouges[0]);
    assert!((gouges[0].position[2] + 1.2).abs() < 1e-9 && (gouges[0].position[0] - 12.0).abs() < 5.5);
    assert!(!cut.ok);
}

#[test]
fn a_rapid_through_the_stock_is_found_at_its_line() {
    let cut = run(json!({
        "program": "G0 X-20 Y0 Z5\nG0 Z-2\nG0 X40\nG0 Z5",
        "tools": [{"kind": "flat", "radius": 3}],
        "stock": {"kind": "box", "min": [0, -10, -10], "max": [20, 10, 0]},
    }));
    assert_eq!(kinds(&cut), [(FindingKind::RapidThroughMaterial, Some(3))]);
    assert!((cut.findings[0].depth - 2.0).abs() < 1e-9);
    assert!((cut.findings[0].volume_mm3 / (20.0 * 6.0 * 2.0) - 1.0).abs() < 0.01);
}

#[test]
fn a_holder_in_a_deep_pocket_is_found_at_the_line_that_takes_it_down() {
    // Ø6 flat, 20 out of the holder (Ø30): stepping down a pocket 4 mm a layer, the holder face
    // reaches the top at the sixth layer (z = −24 puts the face at −4).
    let mut program = String::from("G0 X0 Y0 Z5\n");
    for layer in 1..=6 {
        program.push_str(&format!("G1 Z{} F200\nG1 X10 F600\nG1 X0\n", -4 * layer));
    }
    program.push_str("G0 Z40\n");
    let cut = run(json!({
        "program": program,
        "tools": [{"kind": "flat", "radius": 3, "stickout": 20, "flute_length": 20, "holder_diameter": 30}],
        "stock": {"kind": "box", "min": [-30, -30, -40], "max": [40, 30, 0]},
        "resolution": 0.2,
    }));
    let holder: Vec<_> = cut.findings.iter().filter(|finding| finding.kind == FindingKind::HolderContact).collect();
    assert!(!holder.is_empty(), "{:?}", cut.findings);
    assert_eq!(holder[0].line, Some(17), "{holder:?}");
    assert!((holder[0].depth - 4.0).abs() < 1e-9);
    assert!(cut.findings.iter().all(|finding| finding.kind == FindingKind::HolderContact));
}

#[test]
fn a_tool_cutting_air_most_of_the_time_is_found() {
    // 5 mm of cut, 45 mm in air beyond the stock: 90 % of the cutting time in air.
    let cut = run(json!({
        "program": "G0 X0 Y0 Z5\nG0 Z-1\nG1 X5 F600\nG1 X50\nG0 Z5",
        "tools": [{"kind": "flat", "radius": 2}],
        "stock": {"kind": "box", "min": [-10, -5, -5], "max": [5, 5, 0]},
    }));
    assert!((cut.air_share - 0.9).abs() < 1e-9, "{}", cut.air_share);
    assert_eq!(kinds(&cut), [(FindingKind::RapidThroughMaterial, Some(2)), (FindingKind::AirCutting, Some(4))]);
    assert_eq!(cut.findings[1].share, Some(cut.air_share));
}

#[test]
fn a_tube_is_cut_through_its_wall_only() {
    // A flat Ø4 drilling down through a horizontal tube (bore Ø12, wall 2): two wall pieces.
    let cut = run(json!({
        "program": "G0 X0 Y0 Z12\nG1 Z-12 F100\nG0 Z12",
        "tools": [{"kind": "flat", "radius": 2, "flute_length": 30, "stickout": 40}],
        "stock": {"kind": "tube", "start": [-20, 0, 0], "end": [20, 0, 0], "outer_radius": 8, "inner_radius": 6},
        "resolution": 0.02,
    }));
    // Each wall piece: over the disc x² + y² < 4, the length between the circles of radius 6 and 8
    // (in y–z).
    let mut exact = 0.0;
    let steps = 400;
    for a in 0..steps {
        for b in 0..steps {
            let (x, y) = (
                -2.0 + 4.0 * (f64::from(a) + 0.5) / f64::from(steps),
                -2.0 + 4.0 * (f64::from(b) + 0.5) / f64::from(steps),
            );
            if x * x + y * y < 4.0 {
                exact += 2.0 * ((64.0 - y * y).sqrt() - (36.0 - y * y).sqrt()) * (4.0 / f64::from(steps)).powi(2);
            }
        }
    }
    assert!((cut.removed_volume_mm3 / exact - 1.0).abs() < 0.005, "{} against {exact}", cut.removed_volume_mm3);
}

#[test]
fn refusals_name_their_field() {
    let cases = [
        (
            json!({"program": "G1 X10 Y0 Z0 F100\nG41 X1", "tools": [{"kind": "flat", "radius": 2}],
                "stock": {"kind": "box", "min": [0, 0, -1], "max": [20, 20, 0]}}),
            "program",
        ),
        (
            json!({"program": "G0 X100 Y100 Z5\nG1 X120 F100", "tools": [{"kind": "flat", "radius": 2}],
                "stock": {"kind": "box", "min": [0, 0, -1], "max": [20, 20, 0]}}),
            "stock",
        ),
        (
            json!({"program": "G1 X10 Y0 Z-1 F100", "tools": [{"kind": "flat", "radius": 2}],
                "stock": {"kind": "box", "min": [0, 0, -1], "max": [20, 20, 0]}, "resolution": 0.0001}),
            "resolution",
        ),
        (
            json!({"program": "T3 M6\nG1 X10 Y0 Z-1 F100", "tools": [{"kind": "flat", "radius": 2, "number": 1},
                {"kind": "flat", "radius": 1, "number": 2}],
                "stock": {"kind": "box", "min": [0, 0, -1], "max": [20, 20, 0]}}),
            "tools",
        ),
        (
            json!({"program": "G1 X10 Y0 Z-1 F100", "tools": [{"kind": "flat", "radius": 2, "neck_length": 3}],
                "stock": {"kind": "box", "min": [0, 0, -1], "max": [20, 20, 0]}}),
            "tools[0].neck_length",
        ),
    ];
    for (body, field) in cases {
        let request = request(body);
        let error = verify(&request, &tools(&request), Found::default(), &Run::default()).unwrap_err();
        assert_eq!(error.field(), Some(field), "{error:?}");
    }
}

/// `request` verified with `upload` as its uploaded STL files.
fn run_with(body: Value, upload: &[u8]) -> Result<Cut, crate::error::SolverError> {
    let request = request(body);
    verify(&request, &tools(&request), Found::default(), &Run { upload: Some(upload), ..Run::default() })
}

/// A closed box mesh from `lo` to `hi`, its faces turned inward when `inward`.
fn box_mesh(lo: [f64; 3], hi: [f64; 3], inward: bool) -> Vec<[Vec3; 3]> {
    let mut triangles = box_triangles(Vec3::from(lo), Vec3::from(hi));
    if inward {
        triangles.iter_mut().for_each(|triangle| triangle.swap(1, 2));
    }
    triangles
}

#[test]
fn an_stl_part_is_checked_like_the_same_box() {
    // The dip of `a_dip_into_the_part_is_a_gouge_at_its_line` against the part as an STL file:
    // the same gouges at the same lines; a program that follows the part's top finds none.
    let part = binary_stl(&box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, -1.0], false));
    let body = |program: &str| {
        json!({
            "program": program,
            "tools": [{"kind": "flat", "radius": 5}],
            "stock": {"kind": "box", "min": [-5, -4, -10], "max": [25, 4, 0]},
            "part": {"kind": "mesh"},
        })
    };
    let dip =
        run_with(body("G0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X10\nG1 X12 Z-1.2\nG1 X14 Z-1\nG1 X30\nG0 Z5"), &part).unwrap();
    let gouges: Vec<_> = dip.findings.iter().filter(|finding| finding.kind == FindingKind::Gouge).collect();
    assert_eq!(gouges.iter().map(|gouge| gouge.line).collect::<Vec<_>>(), [Some(4), Some(5)], "{:?}", dip.findings);
    assert!((gouges[0].depth - 0.2).abs() < 1e-6, "{:?}", gouges[0]);
    let level = run_with(body("G0 X-10 Y0 Z5\nG1 Z-0.995 F500\nG1 X30\nG0 Z5"), &part).unwrap();
    assert!(level.ok, "{:?}", level.findings);
    assert!((level.part_volume_mm3.unwrap() - 30.0 * 8.0 * 9.0).abs() < 1e-6);
}

#[test]
fn a_hollow_stl_part_gives_two_intervals_per_ray_through_its_cavity() {
    // A 20 mm cube with a 10 mm cubic cavity under a 5 mm roof, in a block 2 mm higher: a drill
    // down to the part's top gouges nothing; one 12 mm down breaks through the roof into the
    // cavity: a gouge of the roof's 5 mm, not more (the cavity is not part). The block's material
    // in the cavity, which no tool reaches, is left material.
    let mut triangles = box_mesh([0.0, 0.0, -20.0], [20.0, 20.0, 0.0], false);
    triangles.extend(box_mesh([5.0, 5.0, -15.0], [15.0, 15.0, -5.0], true));
    let part = binary_stl(&triangles);
    let body = |program: &str| {
        json!({
            "program": program,
            "tools": [{"kind": "flat", "radius": 1, "flute_length": 20, "stickout": 30}],
            "stock": {"kind": "box", "min": [0, 0, -20], "max": [20, 20, 2]},
            "part": {"kind": "mesh"},
            "resolution": 0.1,
        })
    };
    let roof = run_with(body("G0 X10 Y10 Z5\nG1 Z0 F100\nG0 Z5"), &part).unwrap();
    assert_eq!(kinds(&roof), [(FindingKind::LeftMaterial, None)]);
    assert!((roof.part_volume_mm3.unwrap() - (8000.0 - 1000.0)).abs() < 1e-6);
    let drill = run_with(body("G0 X10 Y10 Z5\nG1 Z-12 F100\nG0 Z5"), &part).unwrap();
    let gouge = drill.findings.iter().find(|finding| finding.kind == FindingKind::Gouge).unwrap();
    assert_eq!(gouge.line, Some(2));
    assert!((gouge.depth - 5.0).abs() < 1e-6, "{gouge:?}");
    assert!((gouge.position[2] + 5.0).abs() < 1e-6, "{gouge:?}");
}

#[test]
fn an_stl_stock_and_part_come_in_one_upload() {
    let stock = binary_stl(&box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, 0.0], false));
    let part = binary_stl(&box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, -1.0], false));
    let cut = run_with(
        json!({
            "program": "G0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X30\nG0 Z5",
            "tools": [{"kind": "flat", "radius": 5}],
            "stock": {"kind": "mesh"},
            "part": {"kind": "mesh"},
        }),
        &Meshes::pack(&part, &stock),
    )
    .unwrap();
    assert!(cut.ok, "{:?}", cut.findings);
    assert!((cut.stock_volume_mm3 - 30.0 * 8.0 * 10.0).abs() < 1e-6);
    assert!((cut.removed_volume_mm3 - 30.0 * 8.0).abs() < 1e-6, "{}", cut.removed_volume_mm3);
}

#[test]
fn bad_stl_parts_are_refused_naming_the_part() {
    let body = json!({
        "program": "G0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X30\nG0 Z5",
        "tools": [{"kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [-5, -4, -10], "max": [25, 4, 0]},
        "part": {"kind": "mesh"},
    });
    let mut open = box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, -1.0], false);
    open.pop();
    let cases = [
        (binary_stl(&open), ErrorCode::MeshNotClosed),
        (binary_stl(&box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, -1.0], true)), ErrorCode::Input),
        (binary_stl(&box_mesh([-5.0, -4.0, -10.0], [25.0, 4.0, 3.0], false)), ErrorCode::Input),
        (binary_stl(&box_mesh([-5.0, -4.0, 5.0], [25.0, 4.0, 8.0], false)), ErrorCode::Input),
        (binary_stl(&box_mesh([-5.0, -4.0, -10.0], [40.0, 4.0, -1.0], false)), ErrorCode::Input),
        (b"not an stl".to_vec(), ErrorCode::MeshFormat),
    ];
    for (index, (bytes, code)) in cases.into_iter().enumerate() {
        let error = run_with(body.clone(), &bytes).unwrap_err();
        assert_eq!((error.code(), error.field()), (code, Some("part")), "case {index}: {error:?}");
    }
    let request = request(body);
    let error = verify(&request, &tools(&request), Found::default(), &Run::default()).unwrap_err();
    assert_eq!(error.field(), Some("part"), "{error:?}");
}

#[test]
fn spindle_power_per_block_from_kienzle_against_the_machine() {
    // A flat Ø10 (2 flutes) slots 2 deep from outside the stock to x = 50 at F600, S10000: it
    // removes 2·(10·50 + π·5²/2) = 1078.54 mm³ in 6 s, Q = 10 785.4 mm³/min. f_z = 600/(10 000·2)
    // = 0.03 mm, h_m = 2·0.03/π = 0.019099 mm, k_c = 1800·h_m^−0.25 = 4841.97 N/mm², so
    // P = 4841.97 · 10 785.4 / 60·10⁶ = 0.87038 kW: over the machine's 0.5 kW.
    let material: crate::material::Material = serde_json::from_value(json!({"kc11": 1800, "mc": 0.25})).unwrap();
    let machine: crate::machine::MachineProfile =
        serde_json::from_value(json!({"block_time_ms": 2, "max_feed": 10000, "spindle_power_kw": 0.5})).unwrap();
    let found = Found { material: Some(&material), machine: Some(&machine) };
    let body = |program: &str| {
        json!({
            "program": program,
            "tools": [{"kind": "flat", "radius": 5, "flutes": 2}],
            "stock": {"kind": "box", "min": [0, -20, -10], "max": [70, 20, 0]},
            "resolution": 0.05,
        })
    };
    let slot = request(body("S10000 M3\nG0 X-10 Y0 Z5\nG0 Z-2\nG1 X50 F600\nG0 Z5"));
    let cut = verify(&slot, &tools(&slot), found, &Run::default()).unwrap();
    let block = cut.blocks.iter().find(|block| block.line == 4).unwrap();
    let power = block.spindle_power_kw.unwrap();
    assert!((power / 0.870_376 - 1.0).abs() < 0.002, "{power}");
    assert_eq!(kinds(&cut), [(FindingKind::SpindlePower, Some(4))]);
    assert_eq!((cut.findings[0].power_kw, cut.findings[0].limit_kw), (Some(power), Some(0.5)));
    // Half the feed per tooth at twice the speed: k_c rises by 2^0.25, the removal rate is the same.
    let fast = request(body("S20000 M3\nG0 X-10 Y0 Z5\nG0 Z-2\nG1 X50 F600\nG0 Z5"));
    let faster =
        verify(&fast, &tools(&fast), Found { material: Some(&material), machine: None }, &Run::default()).unwrap();
    let doubled = faster.blocks.iter().find(|block| block.line == 4).unwrap().spindle_power_kw.unwrap();
    assert!((doubled / power - 2f64.powf(0.25)).abs() < 1e-9, "{doubled} against {power}");
    assert!(faster.ok, "no machine, no limit: {:?}", faster.findings);
    // Without a spindle speed the chip thickness is unknown; a machine without a material has
    // nothing to check.
    let no_speed = request(body("G0 X-10 Y0 Z5\nG0 Z-2\nG1 X50 F600\nG0 Z5"));
    let error = verify(&no_speed, &tools(&no_speed), found, &Run::default()).unwrap_err();
    assert_eq!(error.field(), Some("program"), "{error:?}");
    let error =
        verify(&slot, &tools(&slot), Found { material: None, machine: Some(&machine) }, &Run::default()).unwrap_err();
    assert_eq!(error.field(), Some("machine"), "{error:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn removal_is_bounded_and_cutting_twice_removes_nothing_more(
        points in prop::collection::vec((-12.0..32.0f64, -12.0..12.0f64, -6.0..3.0f64), 2..6),
        radius in 0.5..4.0f64,
        kind in prop::sample::select(vec!["ball", "flat", "bull"]),
    ) {
        let mut program = String::from("F500\n");
        for (x, y, z) in points.iter().chain(&points[..1]) {
            program.push_str(&format!("G1 X{x:.3} Y{y:.3} Z{z:.3}\n"));
        }
        let mut tool = json!({"kind": kind, "radius": radius, "flute_length": 40, "stickout": 40});
        if kind == "bull" {
            tool["corner_radius"] = json!(radius / 2.0);
        }
        let body = |program: &str| json!({
            "program": program, "tools": [tool.clone()], "resolution": 0.25,
            "stock": {"kind": "tube", "start": [-5, 0, -3], "end": [25, 0, -3], "outer_radius": 6, "inner_radius": 3},
        });
        let request = request(body(&program));
        match verify(&request, &tools(&request), Found::default(), &Run::default()) {
            Ok(once) => {
                prop_assert!(once.removed_volume_mm3 >= 0.0);
                prop_assert!(once.removed_volume_mm3 <= once.stock_volume_mm3 + 1e-9);
                prop_assert!((once.final_volume_mm3 + once.removed_volume_mm3 - once.stock_volume_mm3).abs() < 1e-6);
                let twice = run(body(&format!("{program}{program}")));
                prop_assert!((twice.removed_volume_mm3 - once.removed_volume_mm3).abs() < 1e-6,
                    "{} then {}", once.removed_volume_mm3, twice.removed_volume_mm3);
                let replayed: f64 = twice.blocks.iter().filter(|b| b.line > points.len() + 2).map(|b| b.removed_mm3).sum();
                prop_assert!(replayed < 1e-6, "{replayed}");
            }
            Err(error) => prop_assert_eq!(error.field(), Some("stock")),
        }
    }
}

/// Parts' outputs as JSON text, as a job's store keeps them (CBOR there).
#[derive(Default)]
struct Texts(Vec<String>, usize);

impl crate::capability::PartSink for Texts {
    fn put<T: serde::Serialize>(&mut self, value: &T) -> Result<(), crate::error::SolverError> {
        self.0.push(serde_json::to_string(value).expect("a part's output as JSON"));
        Ok(())
    }
}

impl crate::capability::PartSource for Texts {
    fn count(&self) -> usize {
        self.0.len()
    }

    fn next_part<T: serde::de::DeserializeOwned>(&mut self) -> Option<Result<T, crate::error::SolverError>> {
        let text = self.0.get(self.1)?;
        self.1 += 1;
        Some(Ok(serde_json::from_str(text).expect("a part's output read back")))
    }
}

/// The context the server resolves for `request`: its inline tools, and `material` and
/// `machine` when given.
fn context(
    request: &VerifyRequest,
    material: Option<crate::material::Material>,
    machine: Option<crate::machine::MachineProfile>,
) -> crate::capability::Resolved<Option<Tool>> {
    crate::capability::Resolved { tool: None, machine, material, other_tools: tools(request) }
}

/// The answer's JSON of solving `request` whole, or its refusal.
fn whole_json(request: &VerifyRequest, context: &crate::capability::Resolved<Option<Tool>>) -> String {
    use crate::capability::Capability;
    match super::VerifyCapability::solve(request, context.clone(), &Run::default()) {
        Ok(answer) => serde_json::to_string(&answer).expect("JSON"),
        Err(error) => format!("{error:?}"),
    }
}

/// The answer's JSON of solving `parts` (ranges of strips) apart and finishing, or its refusal.
fn parts_json(
    request: &VerifyRequest,
    context: &crate::capability::Resolved<Option<Tool>>,
    parts: &[crate::capability::Part],
) -> String {
    use crate::capability::Capability;
    let mut texts = Texts::default();
    for part in parts {
        if let Err(error) =
            super::VerifyCapability::solve_part(request, context.clone(), part, &Run::default(), &mut texts)
        {
            return format!("{error:?}");
        }
    }
    match super::VerifyCapability::finish(request, context.clone(), &mut texts, &Run::default()) {
        Ok(answer) => serde_json::to_string(&answer).expect("JSON"),
        Err(error) => format!("{error:?}"),
    }
}

/// `strips` cut at `cuts` (each taken modulo `strips`) into consecutive parts.
fn strip_parts(strips: usize, cuts: &[usize]) -> Vec<crate::capability::Part> {
    let mut bounds: Vec<usize> = cuts.iter().map(|cut| cut % strips).filter(|&cut| cut > 0).collect();
    bounds.sort_unstable();
    bounds.dedup();
    bounds.insert(0, 0);
    bounds.push(strips);
    bounds.windows(2).map(|pair| crate::capability::Part { units: pair[0]..pair[1], seconds: 1.0 }).collect()
}

/// The strips of `request`'s dexel grid.
fn strips_of(request: &VerifyRequest) -> usize {
    let job = request.validate(&tools(request), Found::default(), None, crate::capability::Control::default()).unwrap();
    job.grid.strips()
}

#[test]
fn a_verification_split_by_the_cost_model_is_the_whole_one() {
    use crate::capability::{Capability, Sizing, Split};
    // A raster over a dome-shaped part with rapids through the stock, a gouge, a short holder and
    // a spindle over its power; split into parts of the cost model's size, and at every strip.
    let mut program = String::from("T1 M6\nS8000 M3\nG0 X-5 Y-5 Z5\n");
    for row in 0..30 {
        let y = -4.0 + 0.7 * f64::from(row);
        program.push_str(&format!(
            "G1 X-5 Y{y:.3} Z-0.8 F900\nG1 X25 Z{:.3}\nG0 Z2\nG0 X-5\n",
            -1.2 - 0.01 * f64::from(row)
        ));
    }
    program.push_str("G0 X-5 Y19.5\nG0 Z-0.5\nG0 X25\nG0 Z2\nG0 X12 Y19\nG2 X12 Y19 I-2 J0 Z-4 F600\nG0 Z30\nM30\n");
    let request = request(json!({
        "program": program,
        "tools": [{"kind": "ball", "radius": 2, "number": 1, "stickout": 2.5, "flute_length": 2, "holder_diameter": 8}],
        "stock": {"kind": "box", "min": [0, 0, -10], "max": [20, 20, 0]},
        "part": {"kind": "box", "min": [0, 0, -10], "max": [20, 20, -1.25]},
        "resolution": 0.05,
        "material": "steel",
        "machine": "mill",
    }));
    let material: crate::material::Material = serde_json::from_value(json!({"kc11": 1800, "mc": 0.25})).unwrap();
    let machine: crate::machine::MachineProfile =
        serde_json::from_value(json!({"block_time_ms": 2, "max_feed": 10000, "spindle_power_kw": 0.01})).unwrap();
    let context = context(&request, Some(material), Some(machine));
    let whole = whole_json(&request, &context);
    let answer: Value = serde_json::from_str(&whole).expect(&whole);
    let kinds: std::collections::BTreeSet<&str> =
        answer["findings"].as_array().unwrap().iter().map(|finding| finding["kind"].as_str().unwrap()).collect();
    for kind in ["gouge", "rapid_through_material", "holder_contact", "spindle_power", "left_material"] {
        assert!(kinds.contains(kind), "{kind} in {kinds:?}");
    }
    let strips = strips_of(&request);
    assert_eq!(strips, 13);
    let Split { parts, finish_seconds } =
        super::VerifyCapability::split(&request, &context, &Sizing { part_seconds: 0.002, max_parts: 1000 })
            .expect("splits into parts");
    assert!(parts.len() >= 2 && finish_seconds > 0.0, "{parts:?}");
    assert!(parts.windows(2).all(|pair| pair[0].units.end == pair[1].units.start) && parts[0].units.start == 0);
    assert_eq!(parts.last().unwrap().units.end, strips);
    assert!(parts_json(&request, &context, &parts) == whole, "the split answer differs ({} parts)", parts.len());
    let every: Vec<usize> = (1..strips).collect();
    assert!(parts_json(&request, &context, &strip_parts(strips, &every)) == whole, "one part a strip");
    // Large parts: one would do.
    assert!(super::VerifyCapability::split(&request, &context, &Sizing { part_seconds: 1e6, max_parts: 9 }).is_none());
}

#[test]
fn findings_past_the_cap_are_counted_in_program_order_when_split() {
    // 1 300 rapids through the stock, each on its own strips: 1 000 listed, 300 counted, split or not.
    let mut program = String::from("G0 X-2 Y0.5 Z-1\n");
    for k in 0..1300 {
        let y = 0.5 + f64::from(k % 13) * 1.5;
        let x = if k % 2 == 0 { 22.0 } else { -2.0 };
        program.push_str(&format!("G0 Y{y:.2}\nG0 X{x}\n"));
    }
    let request = request(json!({
        "program": program,
        "tools": [{"kind": "flat", "radius": 0.3}],
        "stock": {"kind": "tube", "start": [-5, 10, -3], "end": [25, 10, -3], "outer_radius": 10, "inner_radius": 1},
        "resolution": 0.05,
    }));
    let context = context(&request, None, None);
    let whole = whole_json(&request, &context);
    let answer: Value = serde_json::from_str(&whole).expect(&whole);
    assert_eq!(answer["findings"].as_array().unwrap().len(), 1000);
    assert!(answer["findings_left_off"].as_u64().unwrap() > 0, "{}", answer["findings_left_off"]);
    let strips = strips_of(&request);
    for cuts in [vec![3], vec![1, 5, 9], (1..strips).collect()] {
        assert!(parts_json(&request, &context, &strip_parts(strips, &cuts)) == whole, "cut at {cuts:?}");
    }
}

#[test]
fn refusals_of_a_split_verification_are_the_whole_ones() {
    // The part outside the stock (on one strip only), and a program that never reaches the stock.
    let outside = request(json!({
        "program": "G0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10",
        "tools": [{"kind": "flat", "radius": 1}],
        "stock": {"kind": "box", "min": [0, 0, -5], "max": [10, 10, 0]},
        "part": {"kind": "box", "min": [0, 8, -5], "max": [10, 10, 1]},
        "resolution": 0.1,
    }));
    let away = request(json!({
        "program": "G0 X0 Y0 Z5\nG1 X10 F100",
        "tools": [{"kind": "flat", "radius": 1}],
        "stock": {"kind": "box", "min": [0, 0, -5], "max": [10, 10, 0]},
        "resolution": 0.1,
    }));
    for request in [outside, away] {
        let context = context(&request, None, None);
        let whole = whole_json(&request, &context);
        assert!(whole.contains("Input") || whole.contains("Stock"), "{whole}");
        let strips = strips_of(&request);
        assert!(parts_json(&request, &context, &strip_parts(strips, &[1, 2])) == whole);
    }
}

/// A random program of rapids, lines and helical circles over a 20 × 12 mm area, z from −3 to 2.
fn random_program() -> impl Strategy<Value = String> {
    let step = (0..4usize, -2.0..22.0f64, -2.0..14.0f64, -3.0..2.0f64, 0.5..4.0f64);
    prop::collection::vec(step, 1..25).prop_map(|steps| {
        let mut program = String::from("G0 X-2 Y-2 Z5\n");
        for (kind, x, y, z, radius) in steps {
            program.push_str(&match kind {
                0 => format!("G0 X{x:.3} Y{y:.3} Z{z:.3}\n"),
                1 | 2 => format!("G1 X{x:.3} Y{y:.3} Z{z:.3} F800\n"),
                _ => format!("G3 I{radius:.3} J0 Z{z:.3} F500\n"),
            });
        }
        program
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Any program on a box, a tube or a cylinder, with or without a part, cut in 1 to 5 parts
    /// of whole strips anywhere, finishes as the whole cut, byte for byte (or is refused as it).
    #[test]
    fn a_verification_cut_into_strips_anywhere_is_the_whole_one(
        program in random_program(),
        stock in 0..3usize,
        tool in 0..3usize,
        radius in 0.5..3.0f64,
        with_part in any::<bool>(),
        cuts in prop::collection::vec(0usize..100, 0..4),
    ) {
        let stock = match stock {
            0 => json!({"kind": "box", "min": [0, 0, -6], "max": [20, 12, 0]}),
            1 => json!({"kind": "tube", "start": [0, 6, -5], "end": [20, 6, -5], "outer_radius": 6, "inner_radius": 3}),
            _ => json!({"kind": "cylinder", "start": [10, 6, -6], "end": [10, 6, 0], "radius": 6}),
        };
        let tool = match tool {
            0 => json!({"kind": "ball", "radius": radius, "stickout": 2.5, "holder_diameter": 12}),
            1 => json!({"kind": "flat", "radius": radius, "neck_radius": radius * 0.6, "flute_length": 1}),
            _ => json!({"kind": "bull", "radius": radius, "corner_radius": radius / 3.0}),
        };
        let mut body = json!({"program": program, "tools": [tool], "stock": stock, "resolution": 0.08});
        if with_part {
            body["part"] = json!({"kind": "box", "min": [5, 3, -6], "max": [15, 9, -1.5]});
        }
        let request = request(body);
        let context = context(&request, None, None);
        let strips = strips_of(&request);
        prop_assert!(strips >= 5);
        let parts = strip_parts(strips, &cuts);
        let whole = whole_json(&request, &context);
        prop_assert!(parts_json(&request, &context, &parts) == whole, "{} parts: {}", parts.len(), whole);
    }
}
