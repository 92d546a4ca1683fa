//! The diagnostics of one evaluated path (docs/spec/engagement.md §9): warnings about where the
//! tool touches the stock (none, plunges, back contact, rapids through material, full
//! immersion, several contact zones, jumps of the engaged angle), the path's vertices, the dots
//! engine's resolution, and a force model the dots engine cannot serve.

use super::evaluate::Sampled;
use super::job::{CandidateJob, Job};
use super::request::Engine;
use super::segments::Route;
use super::series;
use super::stock::Base;
use crate::error::Warning;
use crate::planar::turn_angle;
use crate::tool::Tool;

/// Φ at or above this is full immersion (§9 W_FULL_IMMERSION).
const FULL_IMMERSION_DEG: f64 = 179.9;
/// Intervals or positions listed in one warning before "and N more".
const LISTED: usize = 6;

/// What the samples show: `W_NO_CONTACT`, `W_PLUNGE`, `W_RAPID_COLLISION`, `W_FULL_IMMERSION`,
/// `W_MULTI_ARC` and, with a threshold, `W_ENGAGEMENT_SPIKE`.
pub(super) fn sampling(warnings: &mut Vec<Warning>, job: &Job, sampled: &Sampled, engaged_intervals: &[[f64; 2]]) {
    let Sampled { series, statistic, plunges, back, collisions, .. } = sampled;
    if !statistic.iter().any(|s| *s) {
        warnings.push(Warning::new(
            "W_NO_CONTACT",
            if engaged_intervals.is_empty() {
                "no engagement: the tool never touches the stock along this path (check the stock and path coordinates); all series are zero"
            } else {
                "no engagement to evaluate: the tool touches the stock only where it plunges; the statistics are zero"
            },
        ));
    }
    if !plunges.is_empty() {
        warnings.push(Warning::new(
            "W_PLUNGE",
            format!(
                "the tool is already in material where it starts cutting at {}: a plunge (those samples are left out of the statistics)",
                list_intervals(plunges)
            ),
        ));
    }
    if !back.is_empty() {
        let intervals = series.runs(|i| series.marked(i, series::BACK_CONTACT));
        warnings.push(Warning::new(
            "W_PLUNGE",
            format!(
                "engagement on the back half of the tool (ramp, reversal into stock) at {}",
                list_intervals(&intervals)
            ),
        ));
    }
    if !collisions.is_empty() {
        let intervals = series.runs(|i| series.marked(i, series::COLLISION));
        warnings.push(Warning::new(
            "W_RAPID_COLLISION",
            format!(
                "a rapid passes through material at {}: at cutting depth this is a collision (the G-code program retracts to the clearance plane for rapids)",
                list_intervals(&intervals)
            ),
        ));
    }
    let immersion = series.runs(|i| series.engaged_deg[i] >= FULL_IMMERSION_DEG);
    if !immersion.is_empty() {
        warnings.push(Warning::new(
            "W_FULL_IMMERSION",
            format!("full immersion (slotting, Φ ≥ {FULL_IMMERSION_DEG}°) at {}", list_intervals(&immersion)),
        ));
    }
    let multi_arc = series.runs(|i| series.arc_count[i] >= 2);
    if !multi_arc.is_empty() {
        warnings.push(Warning::new(
            "W_MULTI_ARC",
            format!("two or more separate contact zones at {}", list_intervals(&multi_arc)),
        ));
    }
    if let Some(threshold) = job.spike_threshold {
        let spikes = series.runs(|i| {
            i > 0 && statistic[i] && statistic[i - 1] && {
                let jump = (series.engaged_deg[i] - series.engaged_deg[i - 1]).abs();
                jump > threshold
            }
        });
        if !spikes.is_empty() {
            warnings.push(Warning::new(
                "W_ENGAGEMENT_SPIKE",
                format!(
                    "the engaged angle jumps by more than {threshold}° between samples at {} (inside corners: consider a fillet, a feed reduction or trochoidal clearing)",
                    list_intervals(&spikes)
                ),
            ));
        }
    }
}

/// `W_VERTEX`: the path's vertices that turn by more than 1°, each evaluated in the incoming
/// direction.
pub(super) fn vertices(warnings: &mut Vec<Warning>, route: &Route) {
    let vertices: Vec<String> = route
        .pieces
        .windows(2)
        .filter_map(|pair| {
            let out = pair[0].shape.tangent(pair[0].shape.length());
            let into = pair[1].shape.tangent(0.0);
            let turn = turn_angle(&out, &into).to_degrees();
            (turn.abs() > 1.0).then(|| format!("s = {:.3} mm ({turn:+.1}°)", pair[0].end_s()))
        })
        .collect();
    if !vertices.is_empty() {
        let more = vertices.len().saturating_sub(LISTED);
        warnings.push(Warning::new(
            "W_VERTEX",
            format!(
                "{} path vertices turn by more than 1°, each evaluated in the incoming direction: {}{}",
                vertices.len(),
                vertices.iter().take(LISTED).cloned().collect::<Vec<_>>().join(", "),
                if more > 0 { format!(" and {more} more") } else { String::new() }
            ),
        ));
    }
}

/// The dots engine's resolution (`W_RESOLUTION`: step against grid, R/grid) and stock edges
/// shorter than two dots (`W_THIN_FEATURE`); nothing for the exact engine.
pub(super) fn dots(warnings: &mut Vec<Warning>, job: &Job) {
    let (Engine::Dots, Some(cell)) = (job.engine, job.grid) else { return };
    let (step, radius) = (job.step, job.radius);
    let mut notes = Vec::new();
    if step < 4.0 * cell {
        notes.push(format!("step {step} mm is below 4 × grid ({} mm): sampling gaps", 4.0 * cell));
    }
    if radius / cell < 50.0 {
        notes.push(format!(
            "R/grid = {:.1} is below 50: angles near 0°/180° resolve only to about {:.1}°",
            radius / cell,
            (1.0 - 2.0 * cell / radius).clamp(-1.0, 1.0).acos().to_degrees()
        ));
    }
    if step > radius / 10.0 {
        notes.push(format!("step {step} mm is above R/10 ({} mm): coarse in time", radius / 10.0));
    }
    if !notes.is_empty() {
        warnings.push(Warning::new(
            "W_RESOLUTION",
            format!("dots engine at grid {cell} mm, step {step} mm: {}", notes.join("; ")),
        ));
    }
    if let Base::Polygons(outline) = &job.region.base {
        let short = outline
            .rings()
            .iter()
            .flat_map(|ring| ring.iter().zip(ring.iter().cycle().skip(1)))
            .filter(|(a, b)| (*b - *a).norm() < 2.0 * cell)
            .count();
        if short > 0 {
            warnings.push(Warning::new(
                "W_THIN_FEATURE",
                format!("{short} stock edge(s) are shorter than 2 × grid ({} mm): features that small blur or vanish in the dots", 2.0 * cell),
            ));
        }
    }
}

/// `W_FORCE_MODEL`: a rounded end's force model under the dots engine, which has only the full
/// radius's arcs for every height (§11 item 5).
pub(super) fn force_model(warnings: &mut Vec<Warning>, job: &Job, candidate: &CandidateJob, tool: &Tool) {
    if let (Some(model), Engine::Dots) = (&candidate.force, job.engine)
        && model.rounded()
    {
        warnings.push(Warning::new(
            "W_FORCE_MODEL",
            format!(
                "the {} end's chips (h = f_z·sin θ·sin κ) and lever arms are integrated over a_p = {} mm, but engine \"dots\" gives only the full radius's engaged arcs, taken at every height: where the end's smaller sections meet other material (a wall beside the tool, a cut shallower than the corner radius, scallops of an earlier pass, a slot's exit), torque, power and force are off; engine \"exact\" takes each height's own arcs",
                tool.kind.as_str(),
                model.axial_depth
            ),
        ));
    }
}

/// "s = a–b, c–d, … (N in all)".
fn list_intervals(intervals: &[[f64; 2]]) -> String {
    let shown: Vec<String> = intervals
        .iter()
        .take(LISTED)
        .map(|[a, b]| if (b - a).abs() < 1e-9 { format!("{a:.3} mm") } else { format!("{a:.3} mm–{b:.3} mm") })
        .collect();
    let more = intervals.len().saturating_sub(LISTED);
    if more > 0 { format!("s = {} and {more} more", shown.join(", ")) } else { format!("s = {}", shown.join(", ")) }
}
