//! The contour of one layer in traversal order (docs/spec/contour.md §2 symbols, §3.2 classification,
//! §3.9.1–3.9.2 layers and tilted walls): edge directions t_k, air normals n(t_k), signed turns
//! φ_k and material angles α_k, and a segment grid of its edges for the global checks.

use super::prepare::Contour;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::planar::{SegmentGrid, Vec2, miter_point, right_normal, turn_angle};

/// Whether a corner protrudes into the air, sinks into the material, or is too flat to matter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Class {
    /// α < 180°: material protrudes (loop candidate).
    Convex,
    /// α > 180°: an inside corner.
    Reflex,
}

/// One layer's contour, as the tool travels it.
#[derive(Debug, Clone)]
pub(crate) struct Layer {
    /// σ: +1 with the material on the left of travel, −1 on the right.
    pub sigma: f64,
    /// Vertices in traversal order; edge k runs from vertex k to k + 1.
    pub vertices: Vec<Vec2>,
    /// Prepared-contour vertex of traversal vertex k.
    pub prepared_vertex: Vec<usize>,
    /// Prepared-contour edge of traversal edge k.
    pub prepared_edge: Vec<usize>,
    /// Unit direction t_k of edge k.
    pub directions: Vec<Vec2>,
    /// Length of edge k.
    pub lengths: Vec<f64>,
    /// The edges, indexed for distance queries (segment k is edge k).
    pub grid: SegmentGrid,
}

impl Layer {
    /// The contour in traversal order starting with the start edge: counter-clockwise when
    /// `counter_clockwise`, else clockwise along the same start edge; `sigma` is +1 when the
    /// material lies on the left of travel. `shift[e]` moves prepared
    /// edge e towards the air (tilted walls away from their reference height); `cell` is the
    /// grid's smallest cell (the largest query radius).
    pub fn new(
        contour: &Contour,
        start_edge: usize,
        counter_clockwise: bool,
        sigma: f64,
        shift: Option<&[f64]>,
        cell: f64,
    ) -> Result<Self, SolverError> {
        let n = contour.points.len();
        let (prepared_vertex, prepared_edge): (Vec<usize>, Vec<usize>) = (0..n)
            .map(|k| {
                if counter_clockwise {
                    ((start_edge + k) % n, (start_edge + k) % n)
                } else {
                    ((start_edge + 1 + n - k) % n, (start_edge + n - k) % n)
                }
            })
            .unzip();
        let base: Vec<Vec2> = prepared_vertex.iter().map(|&v| contour.points[v]).collect();
        let directions: Vec<Vec2> = (0..n).map(|k| (base[(k + 1) % n] - base[k]).normalize()).collect();
        let vertices = match shift {
            None => base,
            Some(shift) => {
                let offset = |k: usize| shift.get(prepared_edge[k]).copied().unwrap_or(0.0);
                let air = |k: usize| sigma * right_normal(&directions[k]);
                let moved: Vec<Vec2> = (0..n)
                    .map(|k| {
                        let previous = (k + n - 1) % n;
                        miter_point(&base[k], &air(previous), offset(previous), &air(k), offset(k)).unwrap_or(base[k])
                    })
                    .collect();
                for k in 0..n {
                    if (moved[(k + 1) % n] - moved[k]).dot(&directions[k]) <= 0.0 {
                        return Err(SolverError::new(
                            ErrorCode::OffsetCollapse,
                            format!(
                                "with its wall tilts the edge from contour[{}] vanishes at this layer",
                                contour.source[prepared_edge[k]]
                            ),
                        )
                        .at("tilt_deg"));
                    }
                }
                moved
            }
        };
        let lengths = (0..n).map(|k| (vertices[(k + 1) % n] - vertices[k]).norm()).collect();
        let grid = SegmentGrid::new((0..n).map(|k| (vertices[k], vertices[(k + 1) % n])).collect(), cell);
        Ok(Self { sigma, vertices, prepared_vertex, prepared_edge, directions, lengths, grid })
    }

    /// Number of vertices (and edges).
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    /// Index of the vertex or edge before `k`.
    pub fn previous(&self, k: usize) -> usize {
        (k + self.len() - 1) % self.len()
    }

    /// Index of the vertex or edge after `k`.
    pub fn next(&self, k: usize) -> usize {
        (k + 1) % self.len()
    }

    /// n(t_k) = σ·(t_y, −t_x): the unit normal of edge k pointing into the air.
    pub fn air_normal(&self, k: usize) -> Vec2 {
        self.sigma * right_normal(&self.directions[k])
    }

    /// d1 = t_{k−1} and d2 = t_k at vertex k.
    pub fn corner_directions(&self, k: usize) -> (Vec2, Vec2) {
        (self.directions[self.previous(k)], self.directions[k])
    }

    /// φ_k: signed turn at vertex k (C1), counter-clockwise positive.
    pub fn turn(&self, k: usize) -> f64 {
        let (d1, d2) = self.corner_directions(k);
        turn_angle(&d1, &d2)
    }

    /// α_k = π − σφ_k: the material angle at vertex k.
    pub fn material_angle(&self, k: usize) -> f64 {
        std::f64::consts::PI - self.sigma * self.turn(k)
    }

    /// Convex (α < π) or reflex.
    pub fn class(&self, k: usize) -> Class {
        if self.sigma * self.turn(k) > 0.0 { Class::Convex } else { Class::Reflex }
    }
}
