//! Material left and over-cut at each corner (docs/spec/contour.md §3.10): exact areas for ideal execution
//! (inside-corner fillets, dogbone and T-bone reliefs, via `planar`'s exact disk and capsule
//! areas), and predictions under the control models M1 (blend radius) and M2 (servo lag).

use std::f64::consts::PI;

use super::layer::Layer;
use super::pass::{Action, CornerPlan};
use crate::planar::{Vec2, capsule_convex_area, disk_polygon_area, point_segment_distance, signed_area};

/// Material left in and cut beyond the ideal corner.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Material {
    /// Area of material left where it should be air, mm².
    pub left_area: f64,
    /// Distance from the vertex to the cut surface, mm (0 when the vertex is reached).
    pub left_depth: f64,
    /// Area of material cut that should remain, mm².
    pub overcut_area: f64,
    /// Deepest cut beyond the faces, mm.
    pub overcut_depth: f64,
}

/// R1: area between two straight faces at angle `angle` and a tangent fillet of `radius`,
/// R²(cot(α/2) − (π − α)/2).
pub fn fillet_area(radius: f64, angle: f64) -> f64 {
    if radius <= 0.0 {
        return 0.0;
    }
    radius * radius * (1.0 / (0.5 * angle).tan() - 0.5 * (PI - angle))
}

/// Depth of a fillet of `radius` in a corner of `angle`, along the bisector: R(1/sin(α/2) − 1).
pub fn fillet_depth(radius: f64, angle: f64) -> f64 {
    if radius <= 0.0 {
        return 0.0;
    }
    radius * (1.0 / (0.5 * angle).sin() - 1.0)
}

/// The ideal-execution material at a corner of the final pass with tool radius `radius`.
pub(crate) fn ideal(layer: &Layer, corner: &CornerPlan, radius: f64) -> Material {
    if corner.convex {
        return Material::default();
    }
    let k = corner.k;
    let vertex = corner.vertex;
    let (d1, d2) = layer.corner_directions(k);
    let (f1, f2) = (-d1, d2);
    let p = corner.cl_point;
    let air_angle = 2.0 * PI - corner.material_angle;
    let along = (p - vertex).norm() * (0.5 * air_angle).cos();
    let kite = [vertex, vertex + along * f1, p, vertex + along * f2];
    let kite_area = signed_area(&kite).abs();
    match corner.relief {
        None => Material {
            left_area: (kite_area - disk_polygon_area(&p, radius, &kite)).max(0.0),
            left_depth: ((p - vertex).norm() - radius).max(0.0),
            overcut_area: 0.0,
            overcut_depth: 0.0,
        },
        Some(relief) => {
            let target = relief.target;
            let reach = (p - vertex).norm() + (target - vertex).norm() + 2.0 * radius;
            let wedge = [vertex, vertex + 4.0 * reach * f1, vertex + 4.0 * reach * f2];
            let capsule = 2.0 * radius * (target - p).norm() + PI * radius * radius;
            let inside_air = capsule_convex_area(&p, &target, radius, &wedge);
            let depth_beyond = |normal: Vec2| {
                let side = |x: &Vec2| (x - vertex).dot(&normal);
                (radius - side(&p).min(side(&target))).max(0.0)
            };
            Material {
                left_area: (kite_area - capsule_convex_area(&p, &target, radius, &kite)).max(0.0),
                left_depth: (point_segment_distance(&vertex, &p, &target) - radius).max(0.0),
                overcut_area: (capsule - inside_air).max(0.0),
                overcut_depth: depth_beyond(layer.air_normal(layer.previous(k))).max(depth_beyond(layer.air_normal(k))),
            }
        }
    }
}

/// The material left along a stretch the tool cannot follow: the region between the contour
/// from the foot of P on the last followed edge, through the stretch's corners `chain` (traversal
/// order), to the foot of P on the next followed edge, and the tool circle at P.
pub(crate) fn unreached(layer: &Layer, p: &Vec2, chain: &[usize], radius: f64) -> Material {
    let (Some(&first), Some(&last)) = (chain.first(), chain.last()) else {
        return Material::default();
    };
    let foot = |edge: usize| {
        let origin = layer.vertices[edge];
        let t = layer.directions[edge];
        origin + (p - origin).dot(&t) * t
    };
    let mut polygon = vec![*p, foot(layer.previous(first))];
    polygon.extend(chain.iter().map(|&k| layer.vertices[k]));
    polygon.push(foot(last));
    let area = signed_area(&polygon).abs();
    let depth = chain.iter().map(|&k| (layer.vertices[k] - p).norm() - radius).fold(0.0, f64::max);
    Material {
        left_area: (area - disk_polygon_area(p, radius, &polygon)).max(0.0),
        left_depth: depth,
        overcut_area: 0.0,
        overcut_depth: 0.0,
    }
}

/// The material under the control models of the final pass: M1 blends line-to-line corners with
/// `blend_radius`, M2 shrinks arcs by Δ = (v·T)²/(2R) with `lag_product` = (v·T)² in mm².
pub(crate) fn predicted(
    corner: &CornerPlan,
    ideal: &Material,
    radius: f64,
    offset: f64,
    blend_radius: Option<f64>,
    lag_product: Option<f64>,
) -> Material {
    let alpha = corner.material_angle;
    match corner.action {
        Action::Miter => match blend_radius {
            Some(blend) if blend > radius => Material {
                overcut_area: fillet_area(blend - radius, alpha),
                overcut_depth: fillet_depth(blend - radius, alpha),
                ..*ideal
            },
            _ => *ideal,
        },
        Action::Round => match lag_product {
            Some(product) if product > 0.0 => {
                let delta = product / (2.0 * offset);
                let (area, depth) = lag_loss(radius, offset - delta, PI - alpha);
                Material { overcut_area: area, overcut_depth: depth, ..*ideal }
            }
            _ => *ideal,
        },
        Action::Reflex => match blend_radius {
            Some(blend) if blend > 0.0 => {
                let air_angle = 2.0 * PI - alpha;
                Material {
                    left_area: fillet_area(radius + blend, air_angle),
                    left_depth: fillet_depth(radius + blend, air_angle),
                    ..*ideal
                }
            }
            _ => *ideal,
        },
        _ => *ideal,
    }
}

/// M2 round join (R3 and its area): the tool of `radius` runs on an arc of radius `path_radius`
/// about the vertex through the turn `psi`; the material wedge has angle π − ψ. Returns the area
/// cut from the tip and its depth along the bisector.
pub fn lag_loss(radius: f64, path_radius: f64, psi: f64) -> (f64, f64) {
    let reach = |phi: f64| {
        // c' = cos of the angle between the material direction φ (from the inward bisector) and
        // the nearest tool-centre direction on the arc.
        let c = -(phi + 0.5 * psi).cos();
        let discriminant = path_radius * path_radius * (c * c - 1.0) + radius * radius;
        if discriminant <= 0.0 { 0.0 } else { (path_radius * c + discriminant.sqrt()).max(0.0) }
    };
    let half = 0.5 * (PI - psi);
    let steps = 4000;
    let h = half / f64::from(steps);
    let mut sum = 0.0;
    for i in 0..=steps {
        let weight = if i == 0 || i == steps {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let rho = reach(f64::from(i) * h);
        sum += weight * 0.5 * rho * rho;
    }
    (2.0 * sum * h / 3.0, reach(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn closed_forms_of_section_3_10() {
        // Inside corner γ = 90°, r = 2: 0.858407.
        assert_abs_diff_eq!(fillet_area(2.0, PI / 2.0), 0.858407, epsilon = 1e-6);
        // M1 miter on a square corner, ρ_b = 1.5, r = 1: fillet 0.5, 0.05365.
        assert_abs_diff_eq!(fillet_area(0.5, PI / 2.0), 0.05365, epsilon = 1e-5);
        // C2 at 30°, ρ_b = 1, r = 0.5: 0.605763.
        assert_abs_diff_eq!(fillet_area(0.5, PI / 6.0), 0.605763, epsilon = 1e-6);
        // M2 round join, square corner, r = 1, Δ = 0.05: depth 0.069025, area ≈ 0.01846.
        let (area, depth) = lag_loss(1.0, 0.95, PI / 2.0);
        assert_abs_diff_eq!(depth, 0.069025, epsilon = 1e-6);
        assert_abs_diff_eq!(area, 0.01846, epsilon = 1e-5);
    }
}
