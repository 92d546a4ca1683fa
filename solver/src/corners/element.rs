//! The exact tool-centre path of a pass: straight and circular elements with their role
//! (corners.md §1.5 `elements[]`, §3.11 `Element`), and their chording into straight moves.

use crate::planar::{Vec2, arc_steps, circumscribed_arc};

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
