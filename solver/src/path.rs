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

    /// The same path with every point shifted by `offset` (e.g. from ball centre to tip).
    #[must_use]
    pub fn shifted(&self, offset: Vec3) -> Self {
        let moves = self.moves.iter().map(|m| Move { motion: m.motion, to: m.to + offset }).collect();
        Self { moves }
    }
}
