//! The exact tool-centre path of a pass: straight and circular elements with their role
//! (docs/spec/contour.md §1.5 `elements[]`, §3.11 `Element`), and their chording into straight moves.

use crate::machine::BlockRule;
use crate::planar::{Vec2, arc_max_step, arc_steps, circumscribed_arc, circumscribed_arc_steps};

/// How arcs become straight moves: within `tolerance` of the arc, or with the block-time rule
/// (docs/spec/segment.md) at the chord error where one chord lasts one block time at the arc's feed,
/// never coarser than `tolerance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Chording {
    /// The accuracy bound, mm.
    pub tolerance: f64,
    /// The rule at the cutting feed (cutting arcs: round joins) and at the feed of the loops
    /// (the larger of `feed` and `loop_feed`, since a loop runs at one or the other).
    pub rules: Option<(BlockRule, BlockRule)>,
}

impl Chording {
    /// The rule that governs an arc of `kind`.
    pub fn rule(&self, kind: ElementKind) -> Option<&BlockRule> {
        self.rules.as_ref().map(|(cut, turn)| if kind == ElementKind::Loop { turn } else { cut })
    }

    /// The chord tolerance of an arc of `radius` and `kind`: the rule's chord error, never
    /// coarser than `tolerance`; `tolerance` itself where no chord as long as one block fits in
    /// the arc (the blocks there are short whatever the chords; reported).
    pub fn arc_tolerance(&self, radius: f64, kind: ElementKind) -> f64 {
        self.rule(kind)
            .map_or(self.tolerance, |rule| rule.tolerance_for(radius, Some(self.tolerance)).unwrap_or(self.tolerance))
    }

    /// The chord tolerance of `element` (`tolerance` for lines, which need none).
    pub fn of(&self, element: &Element) -> f64 {
        match element {
            Element::Line { .. } => self.tolerance,
            Element::Arc { radius, kind, .. } => self.arc_tolerance(*radius, *kind),
        }
    }
}

/// What an element does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementKind {
    /// Cutting along the contour (including round joins).
    Cut,
    /// Leaving a corner point straight along the extension of the face just cut.
    Exit,
    /// The turn in the air between exit and entry.
    Loop,
    /// Coming back to the corner point along the next face's direction.
    Entry,
    /// Into an inside corner and back (dogbone or T-bone relief); cuts material on purpose.
    Relief,
}

impl ElementKind {
    /// The name used in the reference cases.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Cut => "cut",
            Self::Exit => "exit",
            Self::Loop => "loop",
            Self::Entry => "entry",
            Self::Relief => "relief",
        }
    }
}

/// Sub-arcs of an arc cut by the block-time rule: as few as keep the circumscribed vertices within
/// the rule's chord error `rule_error` (the floor: each sub-arc at least as long as the rule's,
/// so each full segment at least `2R·tan(Δ/2)` ≥ one block), and at least as many as `tolerance`
/// needs (the ceiling there: the accuracy bound wins).
fn rule_steps(radius: f64, sweep: f64, rule_error: f64, tolerance: f64) -> usize {
    rule_steps_bound(radius, sweep, rule_error, tolerance).0
}

/// [`rule_steps`] and whether the tolerance needed more sub-arcs than the rule allows (then the
/// full segments are shorter than a block).
pub(crate) fn rule_steps_bound(radius: f64, sweep: f64, rule_error: f64, tolerance: f64) -> (usize, bool) {
    let step = arc_max_step(radius, rule_error);
    // Saturating float → integer conversion; callers cap the count.
    let block_steps = if step > 0.0 { ((sweep.abs() / step).floor() as usize).max(1) } else { 1 };
    let tolerance_steps = arc_steps(radius, sweep, tolerance);
    (block_steps.max(tolerance_steps), tolerance_steps > block_steps)
}

/// One element of the tool-centre path in the layer plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Element {
    /// A straight move.
    Line {
        /// Start point.
        start: Vec2,
        /// End point.
        end: Vec2,
        /// Role.
        kind: ElementKind,
    },
    /// A circular arc.
    Arc {
        /// Start point.
        start: Vec2,
        /// End point.
        end: Vec2,
        /// Centre.
        centre: Vec2,
        /// Radius.
        radius: f64,
        /// Signed sweep, radians (counter-clockwise positive).
        sweep: f64,
        /// Role.
        kind: ElementKind,
    },
}

impl Element {
    /// The role.
    pub fn kind(&self) -> ElementKind {
        match self {
            Self::Line { kind, .. } | Self::Arc { kind, .. } => *kind,
        }
    }

    /// Start point.
    pub fn start(&self) -> Vec2 {
        match self {
            Self::Line { start, .. } | Self::Arc { start, .. } => *start,
        }
    }

    /// End point.
    pub fn end(&self) -> Vec2 {
        match self {
            Self::Line { end, .. } | Self::Arc { end, .. } => *end,
        }
    }

    /// Exact length.
    pub fn length(&self) -> f64 {
        match self {
            Self::Line { start, end, .. } => (end - start).norm(),
            Self::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// The straight moves of this element as `chording` cuts it: [`Element::chord`] at its
    /// tolerance; under the block-time rule an arc gets the *fewest* equal sub-arcs whose
    /// circumscribed vertices stay within the rule's chord error C (`⌊sweep / Δ(C)⌋`, so every
    /// full segment is at least one block long), but never fewer than `tolerance` needs.
    pub(crate) fn chords(&self, chording: &Chording, max_steps: usize) -> Vec<Vec2> {
        match self {
            Self::Arc { start, end, centre, radius, sweep, kind } if chording.rule(*kind).is_some() => {
                let steps = rule_steps(*radius, *sweep, chording.arc_tolerance(*radius, *kind), chording.tolerance)
                    .min(max_steps.max(1));
                let mut points = circumscribed_arc_steps(centre, start, *sweep, steps);
                if let Some(last) = points.last_mut() {
                    *last = *end;
                }
                points
            }
            _ => self.chord(chording.of(self), max_steps),
        }
    }

    /// Number of straight moves [`Element::chords`] makes (at most).
    pub(crate) fn chords_count(&self, chording: &Chording, max_steps: usize) -> usize {
        self.chord_count(chording.of(self), max_steps)
    }

    /// Number of straight moves [`Element::chord`] makes.
    pub fn chord_count(&self, tolerance: f64, max_steps: usize) -> usize {
        match self {
            Self::Line { .. } => 1,
            Self::Arc { radius, sweep, .. } => arc_steps(*radius, *sweep, tolerance).min(max_steps.max(1)) + 1,
        }
    }

    /// The end points of the straight moves that run this element, after its start: the end for
    /// a line, a circumscribed polyline for an arc (never inside the arc, at most `tolerance`
    /// outside it, its first and last moves tangent to the arc).
    pub fn chord(&self, tolerance: f64, max_steps: usize) -> Vec<Vec2> {
        match self {
            Self::Line { end, .. } => vec![*end],
            Self::Arc { start, end, centre, sweep, .. } => {
                let mut points = circumscribed_arc(centre, start, *sweep, tolerance, max_steps);
                // The exact end point, not its recomputation from the angle.
                if let Some(last) = points.last_mut() {
                    *last = *end;
                }
                points
            }
        }
    }
}
