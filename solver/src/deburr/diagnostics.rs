//! The whole construction at one ridge point (docs/spec/deburr.md §1.5 diagnostics: u, β, L, CL, G1, G2),
//! for inspection and for the tests that check the geometry identities of §2.9.

use serde::Serialize;

use super::centre::Construction;
use super::checks;
use super::envelope::EnvelopePath;
use super::request::{DeburrRequest, Method};
use crate::error::SolverError;
use crate::geometry::array3;
use crate::tool::Tool;

/// The construction at one ridge point, machine coordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PointConstruction {
    /// Ridge point P.
    pub target: [f64; 3],
    /// Ball centre C of the tangent-line construction.
    pub centre: [f64; 3],
    /// Unit ridge tangent t at P (direction of increasing parameter); VP is the plane ⟂ t.
    pub ridge_tangent: [f64; 3],
    /// Unit normal of the cylinder surface into the material, m1.
    pub cylinder_normal: [f64; 3],
    /// Unit normal of the hole wall into the material, m2.
    pub wall_normal: [f64; 3],
    /// Unit bisector u, into the material.
    pub bisector: [f64; 3],
    /// Band edge G1 on the cylinder-surface tangent.
    pub band_edge_cylinder: [f64; 3],
    /// Band edge G2 on the hole-wall tangent.
    pub band_edge_wall: [f64; 3],
    /// β, degrees.
    pub wedge_angle_deg: f64,
    /// L = |PM|, mm.
    pub chord_depth: f64,
    /// CL, mm.
    pub centre_offset: f64,
    /// The exact variant, when the request asks for `method: exact`.
    pub exact: Option<ExactConstruction>,
}

/// The single-section exact construction: band edges on the true surfaces, in VP, and the centre
/// whose own ball section meets them W apart. `method: exact` aims its swept chamfer at these
/// band edges; its centres are not this one's but those of [`ideal_centres`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ExactConstruction {
    /// Ball centre.
    pub centre: [f64; 3],
    /// G1 on the true cylinder surface.
    pub band_edge_cylinder: [f64; 3],
    /// G2 on the true hole wall.
    pub band_edge_wall: [f64; 3],
}

/// The construction at parameter `parameter` of the segment named `segment`, with the request's
/// geometry.
///
/// # Errors
/// The request's validation errors, or `E_INPUT` for an unknown segment or parameter.
pub fn construction_at(
    request: &DeburrRequest,
    tool: &Tool,
    segment: &str,
    parameter: f64,
) -> Result<PointConstruction, SolverError> {
    // The geometry only: the block-time settings do not change the construction.
    let geometry = DeburrRequest { machine: None, block_time_ms: None, ..request.clone() };
    let job = geometry.validate(tool, None)?;
    checks::ridge(&job)?;
    let profile = &job.profile;
    let Some(piece) = profile.segments.iter().find(|s| s.name == segment) else {
        return Err(SolverError::input("segment", format!("this hole has no segment {segment}")));
    };
    if !(0.0..=1.0).contains(&parameter) {
        return Err(SolverError::input("parameter", "parameter must be in [0, 1]"));
    }
    let construction = Construction::for_job(&job);
    let ridge = construction.tangent(&piece.point(profile.radius, parameter));
    let (g1, g2) = ridge.band_edges(construction.half_width);
    let frame = &job.frame;
    // t ∥ m1 × m2; orient it with the direction of travel, found by a small parameter step.
    let mut tangent = ridge.cylinder_normal.cross(&ridge.wall_normal).normalize();
    let step = if parameter < 0.5 { 1e-6 } else { -1e-6 };
    let ahead = construction.tangent(&piece.point(profile.radius, parameter + step)).target - ridge.target;
    if tangent.dot(&ahead) * step < 0.0 {
        tangent = -tangent;
    }
    let exact = match job.method {
        Method::Tangent => None,
        Method::Exact => construction.exact(profile, &ridge).map(|(c, e1, e2)| ExactConstruction {
            centre: array3(&frame.point(&c)),
            band_edge_cylinder: array3(&frame.point(&e1)),
            band_edge_wall: array3(&frame.point(&e2)),
        }),
    };
    Ok(PointConstruction {
        target: array3(&frame.point(&ridge.target)),
        centre: array3(&frame.point(&ridge.centre)),
        ridge_tangent: array3(&frame.vector(&tangent)),
        cylinder_normal: array3(&frame.vector(&ridge.cylinder_normal)),
        wall_normal: array3(&frame.vector(&ridge.wall_normal)),
        bisector: array3(&frame.vector(&ridge.bisector)),
        band_edge_cylinder: array3(&frame.point(&g1)),
        band_edge_wall: array3(&frame.point(&g2)),
        wedge_angle_deg: ridge.wedge_angle().to_degrees(),
        chord_depth: construction.centre_to_chord - ridge.centre_offset,
        centre_offset: ridge.centre_offset,
        exact,
    })
}

/// The ideal centre path of the request's method at `places` (segment name and parameter),
/// machine coordinates: the patent's closed form for `tangent`; for `exact` the path whose swept
/// chamfer meets the true surfaces W apart, solved once for all places. The emitted
/// centres are points of it, and the tolerance bounds the moves' distance from it.
///
/// # Errors
/// The request's validation errors, or `E_INPUT` for an unknown segment or parameter.
pub fn ideal_centres(
    request: &DeburrRequest,
    tool: &Tool,
    places: &[(&str, f64)],
) -> Result<Vec<[f64; 3]>, SolverError> {
    let geometry = DeburrRequest { machine: None, block_time_ms: None, ..request.clone() };
    let job = geometry.validate(tool, None)?;
    checks::ridge(&job)?;
    let profile = &job.profile;
    let construction = Construction::for_job(&job);
    let envelope = (job.method == Method::Exact).then(|| EnvelopePath::solve(&construction, profile));
    places
        .iter()
        .map(|&(segment, parameter)| {
            let Some(index) = profile.segments.iter().position(|s| s.name == segment) else {
                return Err(SolverError::input("segment", format!("this hole has no segment {segment}")));
            };
            if !(0.0..=1.0).contains(&parameter) {
                return Err(SolverError::input("parameter", "parameter must be in [0, 1]"));
            }
            let centre = match &envelope {
                Some(path) => path.centre(&construction, profile, index, parameter),
                None => construction.tangent_centre(&profile.segments[index].point(profile.radius, parameter)),
            };
            Ok(array3(&job.frame.point(&centre)))
        })
        .collect()
}
