//! The chamfer a ball really cuts along the emitted straight moves (docs/spec/deburr.md §2.9 on
//! the swept sphere), measured here independently of kerf's own formulas: the cut volume is the
//! union of the ball at every point of the centre polyline (the limit of a dense sampling of the
//! ball along the moves: each move sweeps a capsule of radius D), and in the ridge's normal plane
//! at each of 720 ridge points the band edges are found by walking along the analytic tube
//! surface and the analytic hole wall from the ridge point until the cut volume ends there. The
//! swept width is the distance between the two edges.
//!
//! Round holes and slots, described by their own frame (docs/spec/deburr.md §1.3: g = O + R_z(θ_A)·R_y(θ_P)·l):
//! the hole wall is the set at distance R2 from the segment x = f, |y| ≤ L_s/2 (a point for a round
//! hole), the ridge x = x(σ), y = y(σ), z = √(R1² − x²) in the local frame, sampled evenly in the
//! profile's arc length σ; positions are reported as "φ", the fraction of the loop in degrees.

use kerf_solver::deburr::{self, Deburr, DeburrRequest, Method};
use kerf_solver::tool::{Tool, ToolKind};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use proptest::prelude::*;

type V = Vector3<f64>;

/// A round cross hole on a tube.
#[derive(Debug, Clone, Copy)]
struct Geometry {
    outer: bool,
    inner_radius: f64,
    outer_radius: f64,
    hole_radius: f64,
    /// L_s, the distance between a slot's end circles along A1; 0 for a round hole.
    slot_length: f64,
    eccentricity: f64,
    arrangement_deg: f64,
    penetration_deg: f64,
    origin: [f64; 3],
    ball: f64,
    cut_amount: f64,
}

impl Geometry {
    fn request(&self, method: Method, tolerance: f64) -> (DeburrRequest, Tool) {
        let mut hole = serde_json::json!({"shape": "round", "radius": self.hole_radius,
            "eccentricity": self.eccentricity, "penetration_angle_deg": self.penetration_deg});
        if self.slot_length > 0.0 {
            hole["shape"] = serde_json::json!("slot");
            hole["centre_distance"] = serde_json::json!(self.slot_length);
        }
        let request = serde_json::from_value(serde_json::json!({
            "tool": {"kind": "ball", "radius": self.ball},
            "workpiece": {"kind": "tube", "origin": self.origin, "arrangement_angle_deg": self.arrangement_deg,
                          "inner_radius": self.inner_radius, "outer_radius": self.outer_radius},
            "hole": hole,
            "edge": if self.outer { "outer" } else { "inner" },
            "cut_amount": self.cut_amount, "tolerance": tolerance,
            "method": if method == Method::Exact { "exact" } else { "tangent" },
        }))
        .expect("valid request");
        (request, Tool::new(ToolKind::Ball, self.ball))
    }

    /// The hole profile's length (two straight sides and two half circles), a lower bound of the
    /// ridge's.
    fn profile_length(&self) -> f64 {
        2.0 * self.slot_length + std::f64::consts::TAU * self.hole_radius
    }

    /// Ridge points enough to see the swept width's dips between the straight moves: at most
    /// [`RIDGE_SPACING`] apart along the profile, and no fewer than `at_least`.
    fn ridge_samples(&self, at_least: usize) -> usize {
        ((self.profile_length() / RIDGE_SPACING).ceil() as usize).max(at_least)
    }

    fn cylinder_radius(&self) -> f64 {
        if self.outer { self.outer_radius } else { self.inner_radius }
    }

    fn width(&self) -> f64 {
        self.cut_amount * std::f64::consts::SQRT_2
    }

    /// R_z(θ_A)·R_y(θ_P).
    fn rotation(&self) -> Matrix3<f64> {
        let (sa, ca) = self.arrangement_deg.to_radians().sin_cos();
        let (sp, cp) = self.penetration_deg.to_radians().sin_cos();
        let rz = Matrix3::new(ca, -sa, 0.0, sa, ca, 0.0, 0.0, 0.0, 1.0);
        let ry = Matrix3::new(cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp);
        rz * ry
    }

    fn local_point(&self, machine: [f64; 3]) -> V {
        self.rotation().transpose() * (V::from(machine) - V::from(self.origin))
    }

    /// Ridge point and unit tangent at the fraction `loop_fraction` ∈ [0, 1) of the profile's
    /// arc length, counter-clockwise from the +x side's start, local frame.
    fn ridge(&self, loop_fraction: f64) -> (V, V) {
        let (r2, b, f) = (self.hole_radius, 0.5 * self.slot_length, self.eccentricity);
        let arc = std::f64::consts::PI * r2;
        let mut sigma = loop_fraction * (4.0 * b + 2.0 * arc);
        // The profile point, its derivative along σ (unit speed), in the x-y plane.
        let (x, y, dx, dy) = if b > 0.0 && sigma < 2.0 * b {
            (f + r2, sigma - b, 0.0, 1.0)
        } else {
            sigma -= 2.0 * b;
            if sigma < arc {
                let phi = sigma / r2;
                (f + r2 * phi.cos(), b + r2 * phi.sin(), -phi.sin(), phi.cos())
            } else if b > 0.0 && sigma < arc + 2.0 * b {
                (f - r2, b - (sigma - arc), 0.0, -1.0)
            } else {
                let phi = std::f64::consts::PI + (sigma - arc - 2.0 * b) / r2;
                (f + r2 * phi.cos(), -b + r2 * phi.sin(), -phi.sin(), phi.cos())
            }
        };
        let r1 = self.cylinder_radius();
        let z = (r1 * r1 - x * x).sqrt();
        (V::new(x, y, z), V::new(dx, dy, -x * dx / z).normalize())
    }

    /// The tube surface: signed radial distance from A1 (the y axis) and its gradient.
    fn cylinder(&self, q: &V) -> (f64, V) {
        let r = q.x.hypot(q.z);
        (r - self.cylinder_radius(), V::new(q.x / r, 0.0, q.z / r))
    }

    /// The hole wall: signed distance from the hole's core (the segment x = f, |y| ≤ L_s/2, seen
    /// along A2) minus R2, and its gradient.
    fn wall(&self, q: &V) -> (f64, V) {
        let dx = q.x - self.eccentricity;
        let dy = q.y.signum() * (q.y.abs() - 0.5 * self.slot_length).max(0.0);
        let r = dx.hypot(dy);
        (r - self.hole_radius, V::new(dx / r, dy / r, 0.0))
    }
}

/// The capsules of the emitted moves (local frame) near one ridge point.
struct Capsules {
    segments: Vec<(V, V)>,
    radius: f64,
}

impl Capsules {
    fn near(centres: &[V], point: &V, radius: f64, reach: f64) -> Self {
        let segments = centres
            .windows(2)
            .map(|pair| (pair[0], pair[1]))
            .filter(|(a, b)| segment_distance(point, a, b) < radius + reach)
            .collect();
        Self { segments, radius }
    }

    fn contains(&self, q: &V) -> bool {
        self.segments.iter().any(|(a, b)| segment_distance(q, a, b) < self.radius)
    }
}

fn segment_distance(p: &V, a: &V, b: &V) -> f64 {
    let ab = b - a;
    let t = if ab.norm_squared() > 0.0 { ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + t * ab)).norm()
}

/// Moves `q` onto the curve where `surface` meets the plane through `p` normal to `t` (Newton on
/// the two constraints, least change).
fn project(surface: &dyn Fn(&V) -> (f64, V), p: &V, t: &V, mut q: V) -> V {
    for _ in 0..8 {
        let (value, gradient) = surface(&q);
        let residual = Vector2::new(value, (q - p).dot(t));
        if residual.norm() < 1e-14 {
            break;
        }
        let jjt = Matrix2::new(gradient.dot(&gradient), gradient.dot(t), gradient.dot(t), t.dot(t));
        let lambda = jjt.try_inverse().expect("surface meets the plane transversally") * residual;
        q -= lambda.x * gradient + lambda.y * t;
    }
    q
}

/// Walks along `surface` in the normal plane (p, t) from p, starting in direction `start`, until
/// it leaves the cut volume; returns the band edge, bisected to 1e-12 mm.
fn band_edge(surface: &dyn Fn(&V) -> (f64, V), p: &V, t: &V, start: &V, cut: &Capsules, longest: f64) -> Option<V> {
    const STEP: f64 = 0.004;
    let mut direction = *start;
    let mut inside = *p;
    let mut walked = 0.0;
    while walked < longest {
        let along = t.cross(&surface(&inside).1).normalize();
        direction = if along.dot(&direction) >= 0.0 { along } else { -along };
        let next = project(surface, p, t, inside + STEP * direction);
        walked += STEP;
        if !cut.contains(&next) {
            let mut outside = next;
            for _ in 0..60 {
                let middle = project(surface, p, t, 0.5 * (inside + outside));
                if cut.contains(&middle) {
                    inside = middle;
                } else {
                    outside = middle;
                }
                if (outside - inside).norm() < 1e-12 {
                    break;
                }
            }
            return Some(0.5 * (inside + outside));
        }
        inside = next;
    }
    None
}

/// Swept width at `samples` ridge points evenly in φ: (φ in degrees, width).
fn swept_widths(geometry: &Geometry, answer: &Deburr, samples: usize) -> Vec<(f64, f64)> {
    let centres: Vec<V> = answer.points.iter().map(|p| geometry.local_point(p.centre)).collect();
    let width = geometry.width();
    let cylinder = |q: &V| geometry.cylinder(q);
    let wall = |q: &V| geometry.wall(q);
    (0..samples)
        .map(|k| {
            let fraction = k as f64 / samples as f64;
            let phi = std::f64::consts::TAU * fraction;
            let (p, t) = geometry.ridge(fraction);
            let cut = Capsules::near(&centres, &p, geometry.ball, 4.0 * width + 1.0);
            assert!(cut.contains(&p), "the ball does not reach the ridge at φ = {:.2}°", phi.to_degrees());
            // Along the tube surface away from the hole; along the wall into the material.
            let away_from_hole = geometry.wall(&p).1;
            let (_, radial) = geometry.cylinder(&p);
            let into_wall = if geometry.outer { -radial } else { radial };
            let longest = 20.0 * width;
            let on_cylinder = band_edge(&cylinder, &p, &t, &away_from_hole, &cut, longest).expect("edge on the tube");
            let on_wall = band_edge(&wall, &p, &t, &into_wall, &cut, longest).expect("edge on the wall");
            (phi.to_degrees(), (on_cylinder - on_wall).norm())
        })
        .collect()
}

/// Largest |swept width − W| and where.
fn worst_error(widths: &[(f64, f64)], width: f64) -> (f64, f64, f64) {
    widths
        .iter()
        .map(|&(phi, w)| (w - width, phi, w))
        .fold((0.0, 0.0, width), |worst, this| if this.0.abs() > worst.0.abs() { this } else { worst })
}

/// Four geometries: tight and loose ridges, centred and off-centre holes.
fn tight_and_loose_geometries() -> [(&'static str, Geometry); 4] {
    let base = Geometry {
        outer: true,
        inner_radius: 20.0,
        outer_radius: 25.0,
        hole_radius: 5.0,
        slot_length: 0.0,
        eccentricity: 0.0,
        arrangement_deg: 0.0,
        penetration_deg: 0.0,
        origin: [0.0; 3],
        ball: 3.0,
        cut_amount: 0.5,
    };
    [
        ("R25 r5 ball 3 Q0.5", base),
        ("R25 r5 ecc 3 20°/35°", Geometry { eccentricity: 3.0, penetration_deg: 20.0, arrangement_deg: 35.0, ..base }),
        ("R10 r8 ball 3 Q0.5", Geometry { inner_radius: 8.5, outer_radius: 10.0, hole_radius: 8.0, ..base }),
        (
            "R10 r8 ecc 0.3 20°/35° ball 4 Q1",
            Geometry {
                inner_radius: 8.6,
                outer_radius: 10.0,
                hole_radius: 8.0,
                eccentricity: 0.3,
                penetration_deg: 20.0,
                arrangement_deg: 35.0,
                ball: 4.0,
                cut_amount: 1.0,
                ..base
            },
        ),
    ]
}

/// The largest spacing of the measured ridge points along the profile: the swept width dips
/// between two moves' ends, and 180 points round a 250 mm slot (1.4 mm apart) missed such a dip
/// by 0.002 mm, the agreement asked of kerf's report; 0.35 mm apart they come within 0.0002 mm.
const RIDGE_SPACING: f64 = 0.4;

/// Width tolerance of the tests: ±0.005 mm at TA 0.002 mm.
const WIDTH_TOLERANCE: f64 = 0.005;
const TOLERANCE: f64 = 0.002;
/// How closely the answer's `swept_width_min/max` (measured by kerf at the targets and between
/// them) must agree with this file's measurement (720 ridge points).
const REPORT_AGREEMENT: f64 = 0.002;

fn warns_width_off(answer: &Deburr) -> bool {
    answer.warnings.iter().any(|w| w.code == "W_WIDTH_OFF")
}

/// What every exact answer must satisfy: the swept chamfer is never wider than W (+ tolerance),
/// the summary's swept range is the measured one, and it is within W ± tolerance everywhere
/// unless W_WIDTH_OFF says otherwise.
fn check_exact(name: &str, geometry: &Geometry, answer: &Deburr, widths: &[(f64, f64)]) -> Result<(), String> {
    let width = geometry.width();
    let (low, high) = widths.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &(_, w)| (l.min(w), h.max(w)));
    let summary = &answer.summary;
    if high > width + WIDTH_TOLERANCE {
        return Err(format!("{name}: the swept chamfer is {high} wide, wider than W = {width}"));
    }
    if (summary.swept_width_min - low).abs() > REPORT_AGREEMENT
        || (summary.swept_width_max - high).abs() > REPORT_AGREEMENT
    {
        return Err(format!(
            "{name}: answer says swept width {}–{}, measured {low}–{high}",
            summary.swept_width_min, summary.swept_width_max
        ));
    }
    let (error, phi, worst) = worst_error(widths, width);
    if error.abs() > WIDTH_TOLERANCE && !warns_width_off(answer) {
        return Err(format!("{name}: swept width {worst} off W by {error} at φ = {phi}° without W_WIDTH_OFF"));
    }
    Ok(())
}

#[test]
fn exact_swept_width_is_w_on_tight_and_loose_ridges() {
    for (index, (name, geometry)) in tight_and_loose_geometries().into_iter().enumerate() {
        let (request, tool) = geometry.request(Method::Exact, TOLERANCE);
        let answer = deburr::solve(&request, &tool).unwrap_or_else(|e| panic!("{name}: {}", e.message()));
        let widths = swept_widths(&geometry, &answer, 720);
        let (error, phi, width) = worst_error(&widths, geometry.width());
        eprintln!(
            "{name}: {} points, worst swept width {width:.5} (W {error:+.5}) at φ = {phi:.1}°",
            answer.points.len() - 1
        );
        check_exact(name, &geometry, &answer, &widths).unwrap();
        if index < 3 {
            assert!(error.abs() <= WIDTH_TOLERANCE, "{name}: swept width {width} off W by {error} at φ = {phi}°");
            assert!(!warns_width_off(&answer), "{name}: {:?}", answer.warnings);
        } else {
            // Geometry 4: near φ = 0 the ridge bends more tightly than a ball of radius 4 can
            // follow, so no placement gives W there without cutting past W nearby. The answer
            // bridges the bend (narrower, never wider) and says so; elsewhere the width is W.
            let warning = answer.warnings.iter().find(|w| w.code == "W_WIDTH_OFF").expect("W_WIDTH_OFF");
            assert!(warning.message.contains("turns too tightly"), "{}", warning.message);
            let near_zero = |phi: f64| !(30.0..=330.0).contains(&phi);
            for &(phi, w) in &widths {
                if !near_zero(phi) && !(170.0..=190.0).contains(&phi) {
                    let error = w - geometry.width();
                    assert!(error.abs() <= WIDTH_TOLERANCE, "{name}: swept width {w} off W by {error} at φ = {phi}°");
                }
            }
        }
    }
}

#[test]
fn tangent_swept_width_is_reported() {
    for (name, geometry) in tight_and_loose_geometries() {
        let (request, tool) = geometry.request(Method::Tangent, TOLERANCE);
        let answer = deburr::solve(&request, &tool).unwrap_or_else(|e| panic!("{name}: {}", e.message()));
        let widths = swept_widths(&geometry, &answer, 720);
        let (error, phi, width) = worst_error(&widths, geometry.width());
        eprintln!("{name} (tangent): worst swept width {width:.5} (W {error:+.5}) at φ = {phi:.1}°");
        let (low, high) =
            widths.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &(_, w)| (l.min(w), h.max(w)));
        let summary = &answer.summary;
        assert!(
            (summary.swept_width_min - low).abs() <= REPORT_AGREEMENT,
            "{name}: {} vs {low}",
            summary.swept_width_min
        );
        assert!(
            (summary.swept_width_max - high).abs() <= REPORT_AGREEMENT,
            "{name}: {} vs {high}",
            summary.swept_width_max
        );
    }
}

fn random_geometry() -> impl Strategy<Value = Geometry> {
    (
        (any::<bool>(), 8.0_f64..60.0, 0.15_f64..0.75, -0.15_f64..0.15),
        (0.15_f64..0.6, 0.08_f64..0.3, -180.0_f64..180.0, -30.0_f64..30.0),
        prop_oneof![Just(0.0), 0.2_f64..3.0],
    )
        .prop_map(
            |(
                (outer, r1, hole_ratio, eccentricity_ratio),
                (ball_ratio, cut_ratio, arrangement, penetration),
                slot_ratio,
            )| {
                let hole_radius = r1 * hole_ratio;
                // Keep the ridge clear of the cylinder's flanks (|f| + R2 ≤ 0.8·R1) and the wall thick.
                let room = (0.8 * r1 - hole_radius).max(0.0);
                let eccentricity = (eccentricity_ratio * r1).clamp(-room, room);
                let ball = (hole_radius * ball_ratio).clamp(0.5, 6.0);
                let (inner_radius, outer_radius) = if outer { (r1 * 0.9, r1) } else { (r1, r1 * 1.3) };
                Geometry {
                    outer,
                    inner_radius,
                    outer_radius,
                    hole_radius,
                    slot_length: slot_ratio * hole_radius,
                    eccentricity,
                    arrangement_deg: arrangement,
                    penetration_deg: penetration,
                    origin: [3.0, -2.0, 1.0],
                    ball,
                    cut_amount: ball * cut_ratio,
                }
            },
        )
}

/// A long slot on the inside edge of a thick tube, a case random search found: its ridge is 254 mm
/// long, and kerf's reported narrowest swept width (between two moves) is there, 0.002 mm below
/// what 180 evenly spread ridge points see.
#[test]
fn exact_swept_width_on_a_long_slot_inside() {
    let geometry = Geometry {
        outer: false,
        inner_radius: 50.551,
        outer_radius: 65.716,
        hole_radius: 28.694,
        slot_length: 36.899,
        eccentricity: 7.313,
        arrangement_deg: 35.0,
        penetration_deg: 20.0,
        origin: [3.0, -2.0, 1.0],
        ball: 6.0,
        cut_amount: 0.48,
    };
    let (request, tool) = geometry.request(Method::Exact, TOLERANCE);
    let answer = deburr::solve(&request, &tool).expect("an exact answer");
    let widths = swept_widths(&geometry, &answer, geometry.ridge_samples(180));
    if let Err(message) = check_exact("long slot inside", &geometry, &answer, &widths) {
        panic!("{message}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random round holes and slots: the exact method's swept chamfer is W wide within ±0.005 mm at
    /// TA 0.002 mm, or the answer says where and why not (and is then never wider than W).
    #[test]
    fn exact_swept_width_on_random_holes(geometry in random_geometry()) {
        let (request, tool) = geometry.request(Method::Exact, TOLERANCE);
        let answer = match deburr::solve(&request, &tool) {
            Ok(answer) => answer,
            Err(error) => {
                prop_assert!(["E_FAR_GOUGE", "E_BALL_MISSES_EDGE"].contains(&error.code().as_str()), "{}: {}", error.code().as_str(), error.message());
                return Ok(());
            }
        };
        // Every 0.1 mm: the answer measures its width between its targets too, and a dip there
        // can be narrower than the 0.4 mm the fixed cases are sampled at.
        let widths = swept_widths(&geometry, &answer, 4 * geometry.ridge_samples(180));
        if let Err(message) = check_exact("random", &geometry, &answer, &widths) {
            prop_assert!(false, "{}", message);
        }
    }
}
