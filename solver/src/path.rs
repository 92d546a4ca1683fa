//! Typed tool motion: what every path-producing capability hands to the G-code post.

use crate::geometry::Vec3;

/// How the control moves to the next point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Positioning at rapid traverse (G00); never cuts.
    Rapid,
    /// Straight cutting move (G01) at `feed` mm/min.
    Linear {
        /// Feed in mm/min.
        feed: f64,
    },
    /// Circular (or, with a Z change, helical) cutting move in the XY plane (G17) about `centre`
    /// (its z is ignored) at `feed` mm/min: G02 clockwise, G03 counter-clockwise seen from +Z.
    /// Starts where the previous move ended; start and end are the same distance from `centre`.
    Arc {
        /// Feed in mm/min.
        feed: f64,
        /// Centre of the circle (x, y; z ignored).
        centre: Vec3,
        /// Clockwise (G02) seen from +Z, else counter-clockwise (G03).
        clockwise: bool,
    },
}

impl Motion {
    /// The feed of a cutting move, `None` for a rapid.
    pub fn feed(&self) -> Option<f64> {
        match *self {
            Self::Rapid => None,
            Self::Linear { feed } | Self::Arc { feed, .. } => Some(feed),
        }
    }
}

/// One move: a motion to an end point of the programmed (control) point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Rapid or feed.
    pub motion: Motion,
    /// End point in machine/work coordinates, mm.
    pub to: Vec3,
}

/// A sequence of moves of the programmed point, starting wherever the previous program left the
/// tool (the post positions at the clearance height first).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Toolpath {
    /// The moves in order.
    pub moves: Vec<Move>,
}

impl Toolpath {
    /// Appends a rapid move.
    pub fn rapid(&mut self, to: Vec3) {
        self.moves.push(Move { motion: Motion::Rapid, to });
    }

    /// Appends a cutting move at `feed` mm/min.
    pub fn linear(&mut self, to: Vec3, feed: f64) {
        self.moves.push(Move { motion: Motion::Linear { feed }, to });
    }

    /// Appends a circular move in the XY plane about `centre` (helical when `to.z` differs from
    /// the current z).
    pub fn arc(&mut self, to: Vec3, centre: Vec3, clockwise: bool, feed: f64) {
        self.moves.push(Move { motion: Motion::Arc { feed, centre, clockwise }, to });
    }

    /// Appends the arc (helix when `end.z` differs from `start.z`) from `start` to `end` about
    /// `centre` sweeping `sweep` radians (counter-clockwise positive) as circular moves of at most
    /// half a turn each: a block whose end equals its start would be a full circle or nothing,
    /// depending on the control. The last move ends exactly at `end`; the others on the circle
    /// through `start`, with Z in proportion to the angle.
    pub fn arc_sweep(&mut self, start: Vec3, end: Vec3, centre: Vec3, sweep: f64, feed: f64) {
        let pieces = (sweep.abs() / std::f64::consts::PI).ceil().max(1.0);
        let radius = ((start.x - centre.x).powi(2) + (start.y - centre.y).powi(2)).sqrt();
        let first = (start.y - centre.y).atan2(start.x - centre.x);
        // A float → integer conversion of a small positive count (sweeps are at most a few turns).
        let count = pieces as usize;
        for index in 1..=count {
            let fraction = index as f64 / pieces;
            let to = if index == count {
                end
            } else {
                let angle = first + sweep * fraction;
                Vec3::new(
                    centre.x + radius * angle.cos(),
                    centre.y + radius * angle.sin(),
                    start.z + (end.z - start.z) * fraction,
                )
            };
            self.arc(to, centre, sweep < 0.0, feed);
        }
    }

    /// The same path with every point shifted by `offset` (e.g. from ball centre to tip).
    #[must_use]
    pub fn shifted(&self, offset: Vec3) -> Self {
        let moves = self
            .moves
            .iter()
            .map(|m| {
                let motion = match m.motion {
                    Motion::Arc { feed, centre, clockwise } => Motion::Arc { feed, centre: centre + offset, clockwise },
                    other => other,
                };
                Move { motion, to: m.to + offset }
            })
            .collect();
        Self { moves }
    }
}
