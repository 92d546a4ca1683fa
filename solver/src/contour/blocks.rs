//! What the block-time rule did to a contour's arcs (docs/spec/segment.md §4 and §6), and the
//! warnings that explain its short blocks; the figures themselves are
//! [`crate::machine::PathBlocks`].

use super::element::{Chording, Element, rule_steps_bound};
use super::pass::PassPlan;
use crate::error::Warning;

/// What the rule did to the arcs of the first layer's passes: the finest chord tolerance, and
/// the warnings for arcs too tight for one block at their feed (docs/spec/segment.md E3) and for arcs whose
/// block-length chord error the `tolerance` overrides (E4).
pub(crate) fn arc_report(passes: &[PassPlan], chording: &Chording) -> (Option<f64>, Vec<Warning>) {
    let mut finest: Option<f64> = None;
    // (count, smallest radius, largest feasible feed) for E3; (count, largest feed) for E4.
    let mut infeasible = (0usize, f64::INFINITY, f64::INFINITY);
    let mut overridden = (0usize, f64::INFINITY);
    for element in passes.iter().flat_map(|p| &p.elements) {
        let Element::Arc { radius, sweep, kind, .. } = element else { continue };
        let Some(rule) = chording.rule(*kind) else { continue };
        let tolerance = chording.arc_tolerance(*radius, *kind);
        finest = Some(finest.map_or(tolerance, |f: f64| f.min(tolerance)));
        if let Err(error) = rule.chord_error(*radius) {
            infeasible.0 += 1;
            infeasible.1 = infeasible.1.min(*radius);
            infeasible.2 = infeasible.2.min(error.feed_limit);
        } else if rule_steps_bound(*radius, *sweep, tolerance, chording.tolerance).1 {
            // The tolerance needs more (so shorter) chords than a block allows: at or above the
            // rule's chord error, or just below it where whole chords do not fit the sweep.
            overridden.0 += 1;
            overridden.1 = overridden.1.min(rule.feed_for_tolerance(*radius, chording.tolerance));
        }
    }
    let mut warnings = Vec::new();
    if infeasible.0 > 0 {
        warnings.push(Warning::new(
            "W_INFEASIBLE_FEED_FOR_RADIUS",
            format!(
                "{} arcs per layer (smallest radius {:.4} mm) cannot hold one block at their feed: they are chorded at \
                 the tolerance and their blocks are short; {:.0} mm/min is the largest feed for them",
                infeasible.0, infeasible.1, infeasible.2
            ),
        ));
    }
    if overridden.0 > 0 {
        warnings.push(Warning::new(
            "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
            format!(
                "{} arcs per layer need a chord error above the tolerance {} mm for blocks of one block time: the \
                 tolerance wins and their blocks are short; below about {:.0} mm/min they fit within it",
                overridden.0, chording.tolerance, overridden.1
            ),
        ));
    }
    (finest, warnings)
}
