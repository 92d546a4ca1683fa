//! Validity limits and warnings of docs/spec/deburr.md §4 that look at the geometry as a whole: whether
//! the ridge exists, the far-side gouge, tool access for inner edges and chamfer overlap.

use super::centre::{Construction, RidgeCentre};
use super::job::Job;
use super::profile::Profile;
use super::request::Edge;
use super::tolerance::Target;
use crate::error::ErrorCode;
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;

/// Upper bound on ridge samples for the far-gouge check.
const MAX_RIDGE_SAMPLES: usize = 20_000;

/// Checks that the ridge exists and the ball can cut the band (E_NOT_THROUGH, E_HOLE_TOO_LARGE,
/// E_WIDTH_VS_BALL); returns the near-tangent warning when the ridge comes close to Z = 0.
pub(crate) fn ridge(job: &Job) -> Result<Vec<Warning>, SolverError> {
    let reach = job.profile.max_abs_x();
    let r1 = job.cylinder_radius;
    if reach >= r1 {
        return Err(SolverError::new(
            ErrorCode::HoleTooLarge,
            format!(
                "hole too large: |eccentricity| + half-width = {reach} mm must be below the cylinder radius {r1} mm"
            ),
        )
        .at("hole.radius"));
    }
    if let Some((inner, _)) = job.tube_radii
        && job.edge == Edge::Outer
        && reach >= inner
    {
        return Err(SolverError::new(
            ErrorCode::NotThrough,
            format!(
                "the hole reaches |x| = {reach} mm across the tube, not below the inner radius {inner} mm: it does \
                not meet the bore as a separate loop"
            ),
        )
        .at("hole.radius"));
    }
    let ball = job.tool.radius;
    if job.width >= 2.0 * ball {
        return Err(SolverError::new(
            ErrorCode::WidthVsBall,
            format!(
                "ball too small for Q: the band width W = {:.4} mm must be below the ball diameter {} mm",
                job.width,
                2.0 * ball
            ),
        )
        .at("cut_amount"));
    }
    let mut warnings = Vec::new();
    let lowest = (r1 * r1 - reach * reach).sqrt();
    if lowest < 0.05 * r1 {
        warnings.push(Warning::new(
            "W_NEAR_TANGENT",
            format!(
                "the ridge comes down to {lowest:.4} mm from the axis plane (< 5 % of R1): the edge is nearly tangent"
            ),
        ));
    }
    Ok(warnings)
}

/// Dense samples of the ridge (local frame), per segment, for the far-gouge check.
struct RidgeSamples {
    points: Vec<Vec3>,
    /// First sample index and sample count of each segment.
    segments: Vec<(usize, usize)>,
    /// Bounding spheres of runs of 16 samples: centre, radius, first index.
    chunks: Vec<(Vec3, f64, usize)>,
}

const CHUNK: usize = 16;

impl RidgeSamples {
    fn new(profile: &Profile, cylinder_radius: f64, ball_radius: f64) -> Self {
        let spacing = profile.radius.min(ball_radius) / 8.0;
        let lengths: Vec<f64> = profile.segments.iter().map(|s| s.length(profile.radius)).collect();
        let total: f64 = lengths.iter().sum();
        let scale = (total / spacing / MAX_RIDGE_SAMPLES as f64).max(1.0);
        let mut points = Vec::new();
        let mut segments = Vec::new();
        for (segment, length) in profile.segments.iter().zip(&lengths) {
            let count = ((length / spacing / scale).ceil() as usize).max(8);
            segments.push((points.len(), count));
            for j in 0..count {
                let p = segment.point(profile.radius, j as f64 / count as f64);
                points.push(Vec3::new(p.x, p.y, (cylinder_radius * cylinder_radius - p.x * p.x).sqrt()));
            }
        }
        let chunks = points
            .chunks(CHUNK)
            .enumerate()
            .map(|(index, chunk)| {
                let centre = chunk.iter().sum::<Vec3>() / chunk.len() as f64;
                let radius = chunk.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
                (centre, radius, index * CHUNK)
            })
            .collect();
        Self { points, segments, chunks }
    }

    fn nearest_index(&self, target: &Target) -> usize {
        let (first, count) = self.segments[target.segment];
        (first + (target.parameter * count as f64).round() as usize) % self.points.len()
    }
}

/// E_FAR_GOUGE (docs/spec/deburr.md §4): for every centre, the ridge samples inside the ball must form
/// one run around its own target and must not be the whole ridge. The ridge samples set the
/// check's resolution, so a loop with many more points than samples is checked at two centres
/// per sample spacing (every centre otherwise).
pub(crate) fn far_gouge(job: &Job, targets: &[Target], centres: &[Vec3]) -> Result<(), SolverError> {
    let ball = job.tool.radius;
    let samples = RidgeSamples::new(&job.profile, job.cylinder_radius, ball);
    let total = samples.points.len();
    let limit = ball * ball * (1.0 - 1e-9);
    let inside = |centre: &Vec3, k: usize| (samples.points[k] - centre).norm_squared() < limit;
    let stride = (targets.len() / (2 * total)).max(1);
    for (target, centre) in targets.iter().zip(centres).step_by(stride) {
        let home = samples.nearest_index(target);
        let (mut ahead, mut behind) = (0, 0);
        if inside(centre, home) {
            while ahead + 1 < total && inside(centre, (home + ahead + 1) % total) {
                ahead += 1;
            }
            while ahead + behind + 1 < total && inside(centre, (home + total - behind - 1) % total) {
                behind += 1;
            }
            if ahead + behind + 1 == total {
                return Err(far_gouge_error(job, target, "the ball contains the whole ridge"));
            }
        }
        let run_start = (home + total - behind) % total;
        let run_length = if inside(centre, home) { ahead + behind + 1 } else { 0 };
        for &(chunk_centre, chunk_radius, first) in &samples.chunks {
            if (chunk_centre - centre).norm() - chunk_radius >= ball {
                continue;
            }
            for k in first..(first + CHUNK).min(total) {
                let in_run = (k + total - run_start) % total < run_length;
                if !in_run && inside(centre, k) {
                    return Err(far_gouge_error(job, target, "the ball also reaches another part of the ridge"));
                }
            }
        }
    }
    Ok(())
}

fn far_gouge_error(job: &Job, target: &Target, what: &str) -> SolverError {
    let segment = &job.profile.segments[target.segment];
    SolverError::new(
        ErrorCode::FarGouge,
        format!(
            "{what} at {} s = {:.4}: ball radius {} mm is too large for this hole (R2 = {} mm)",
            segment.name, target.parameter, job.tool.radius, job.profile.radius
        ),
    )
    .at("tool")
}

/// Access for inner edges (W_INNER_ACCESS, E_NECK_COLLISION) and whether the approach down the
/// hole axis is possible (returned as the error a G-code request would get).
pub(crate) fn inner_access(
    job: &Job,
    ridges: &[RidgeCentre],
    shank_direction: &Vec3,
) -> (Vec<Warning>, Option<SolverError>) {
    let mut warnings = Vec::new();
    if job.edge != Edge::Inner {
        return (warnings, None);
    }
    let profile = &job.profile;
    let ball = job.tool.radius;
    let approach = (ball >= profile.inscribed_radius()).then(|| {
        SolverError::new(
            ErrorCode::NoApproach,
            format!(
                "the ball (radius {ball} mm) cannot pass through the hole (half-width {} mm), so no approach down the \
                hole axis exists; approach from the bore end instead",
                profile.inscribed_radius()
            ),
        )
        .at("tool")
    });
    let Some(neck) = job.tool.neck_radius else {
        warnings.push(Warning::new(
            "W_INNER_ACCESS",
            "on an inner edge the shank above the ball passes through the hole next to the wall; a plain ball end \
             mill's shank rubs it. Use a lollipop or back-deburring cutter and register its neck_radius so kerf can \
             check the clearance",
        ));
        return (warnings, approach);
    };
    // The hole is convex, so along the straight neck axis the wall distance is largest at an end:
    // checking the ridge height and the top of the wall suffices.
    let mut tightest = f64::INFINITY;
    for ridge in ridges {
        let mut heights = vec![ridge.target.z];
        heights.extend(job.top_distance);
        for height in heights {
            let t = (height - ridge.centre.z) / shank_direction.z;
            let axis = ridge.centre + t * shank_direction;
            tightest = tightest.min(-profile.signed_distance(axis.x, axis.y).0 - neck);
        }
    }
    if tightest < 0.0 {
        let error = SolverError::new(
            ErrorCode::NeckCollision,
            format!("the neck (radius {neck} mm) would cut the hole wall: it is short of room by {:.4} mm", -tightest),
        )
        .at("tool.neck_radius");
        return (warnings, Some(approach.unwrap_or(error)));
    }
    (warnings, approach)
}

/// W_OVERLAP: on a tube, whether the same chamfer on the other edge would meet this one.
pub(crate) fn overlap(job: &Job, construction: &Construction, ridges: &[RidgeCentre]) -> Option<Warning> {
    let (inner, outer) = job.tube_radii?;
    let mut worst: Option<(f64, f64)> = None;
    for ridge in ridges {
        let (_, on_wall) = ridge.band_edges(construction.half_width);
        let leg_along_axis = (on_wall - ridge.target).z.abs();
        let x = ridge.target.x;
        let wall = (outer * outer - x * x).sqrt() - (inner * inner - x * x).sqrt();
        if 2.0 * leg_along_axis >= wall && worst.is_none_or(|(w, _)| wall < w) {
            worst = Some((wall, leg_along_axis));
        }
    }
    worst.map(|(wall, leg)| {
        Warning::new(
            "W_OVERLAP",
            format!(
                "the hole wall is only {wall:.4} mm long at its thinnest and this chamfer takes {leg:.4} mm of it: the \
                 same chamfer on the other edge would meet it"
            ),
        )
    })
}

/// W_SHANK_CLEARANCE: on a tube's outer edge, whether the vertical shank above the ball (radius:
/// the tool's neck radius, else the ball's) clears the tube. Seen along the horizontal tube axis the
/// shank is a vertical strip above the centre and the tube a disc of radius R_T; the hole is
/// ignored, which errs on the side of warning.
pub(crate) fn outer_shank(job: &Job, ridges: &[RidgeCentre]) -> Option<Warning> {
    let (_, outer) = job.tube_radii?;
    if job.edge != Edge::Outer {
        return None;
    }
    let frame = &job.frame;
    let axis = frame.vector(&Vec3::y());
    let across = Vec3::z().cross(&axis).normalize();
    let shank = job.tool.neck_radius.unwrap_or(job.tool.radius);
    let mut blocked = 0;
    let mut first: Option<f64> = None;
    for ridge in ridges {
        let centre = frame.point(&ridge.centre);
        let u = (centre - frame.origin).dot(&across);
        let nearest = 0.0_f64.clamp(u - shank, u + shank);
        if nearest.abs() >= outer {
            continue;
        }
        let top = frame.origin.z + (outer * outer - nearest * nearest).sqrt();
        if top > centre.z + 1e-9 {
            blocked += 1;
            first.get_or_insert(top - centre.z);
        }
    }
    first.map(|overlap| {
        Warning::new(
            "W_SHANK_CLEARANCE",
            format!(
                "at {blocked} points the vertical shank above the ball (radius {shank} mm) would meet the tube (by up to \
                 {overlap:.3} mm at the first): a vertical tool cannot reach that part of the edge; turn the part so the \
                 hole points up"
            ),
        )
    })
}
