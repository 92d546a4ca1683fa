//! Exclusion of low-angle passes before prediction (docs/spec/predict.md §3.4, claim 8): where
//! the tool axis is nearly along the surface normal deflection hardly matters, so passes whose
//! finished surface lies only at small contact angles are not predicted.
//!
//! One view from below over the stock's footprint: at every pixel the lowest point of all the
//! swept capsules is the final machined surface (§3.5), owned by the segment that reaches
//! lowest, and its contact angle is the angle between the tool axis and the ball radius to that
//! point. θ_max of a pass is the largest angle among the pixels it owns inside the stock. A
//! pass owning no pixel keeps its prediction (it may still leave a surface narrower than a
//! pixel).

use super::capsule::Capsule;
use super::job::Job;
use super::passes::{PathModel, Stamps};
use crate::geometry::Vec3;

/// Most pixels of the global view: the pixel grows past R/32 on a large footprint to stay
/// within this.
pub(crate) const MAX_PIXELS: f64 = 1e6;

/// The global view's pixel size for a tool of radius `radius` over `footprint`, mm.
pub(crate) fn pixel_size(radius: f64, footprint: ([f64; 2], [f64; 2])) -> f64 {
    let (lo, hi) = footprint;
    let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(0.0);
    (radius / 32.0).max((area / MAX_PIXELS).sqrt())
}

/// θ_max of every pass, degrees; `None` for a pass that owns no pixel of the finished surface.
pub(crate) fn max_contact_angles(job: &Job, path: &PathModel) -> Vec<Option<f64>> {
    let radius = job.radius;
    let r2 = radius * radius;
    let footprint = job.stock.footprint();
    let pixel = pixel_size(radius, footprint);
    let (lo, hi) = footprint;
    let columns = ((hi[0] - lo[0]) / pixel).ceil().max(0.0) as usize;
    let rows = ((hi[1] - lo[1]) / pixel).ceil().max(0.0) as usize;
    let capsules: Vec<(Capsule, Vec3, Vec3)> = (0..path.segments.len())
        .map(|index| {
            let (a, b) = path.ends(index);
            (Capsule::new(a, b), a, b)
        })
        .collect();
    let mut angles: Vec<Option<f64>> = vec![None; path.passes.len()];
    let mut stamps = Stamps::default();
    let mut near = Vec::new();
    let eps = 1e-9 * radius;
    for row in 0..rows {
        let y = lo[1] + (row as f64 + 0.5) * pixel;
        for column in 0..columns {
            let x = lo[0] + (column as f64 + 0.5) * pixel;
            near.clear();
            path.near(&Vec3::new(x, y, 0.0), radius, &mut stamps, &mut near);
            let mut lowest: Option<(f64, usize)> = None;
            for &index in &near {
                let index = index as usize;
                if let Some(z) = capsules[index].0.entry_z(x, y, r2)
                    && lowest.is_none_or(|(best, _)| z < best - eps)
                {
                    lowest = Some((z, index));
                }
            }
            let Some((z, index)) = lowest else { continue };
            let q = Vec3::new(x, y, z);
            // Above the stock the surface there is the stock's own; nobody owns it.
            if !job.stock.contains(&q, eps) {
                continue;
            }
            let Some(pass) = path.segments[index].pass else { continue };
            let (_, a, b) = capsules[index];
            let axis = b - a;
            let t = if axis.norm_squared() > 0.0 {
                ((q - a).dot(&axis) / axis.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let centre = a + t * axis;
            let angle = ((centre.z - q.z) / radius).clamp(-1.0, 1.0).acos().to_degrees();
            let slot = &mut angles[pass];
            *slot = Some(slot.map_or(angle, |current: f64| current.max(angle)));
        }
    }
    angles
}
