//! Inside-corner relief (beyond the patent; docs/spec/contour.md §3.10 says a round tool always leaves a
//! fillet of radius r in an inside corner): from the corner's CL point P the tool runs in a
//! straight line until its circle passes through the vertex (a distance δ from it on passes with
//! allowance δ), then straight back to P.
//!
//! * dogbone: along the bisector, to D = V + o·u with u the unit vector from V towards P;
//! * T-bone: along one face's offset line, to T = V + o·n(t_e), the foot of V on that line; the
//!   cut goes into the other face.

use super::layer::Layer;
use super::request::{Relief, TboneEdge};
use crate::planar::Vec2;

/// A relief at one inside corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReliefShape {
    /// `dogbone` or `tbone`.
    pub style: Relief,
    /// Where the tool centre turns back.
    pub target: Vec2,
    /// T-bone: the traversal edge it runs along.
    pub along_edge: Option<usize>,
}

/// The relief of `style` at inside vertex `k` of the layer, with CL point `p` and offset `o`.
/// `request_order`: whether the traversal follows the request's point order (for `previous` and
/// `next`).
pub(crate) fn shape(
    layer: &Layer,
    k: usize,
    p: &Vec2,
    offset: f64,
    style: Relief,
    edge: TboneEdge,
    request_order: bool,
) -> ReliefShape {
    let vertex = layer.vertices[k];
    match style {
        Relief::Tbone => {
            let (incoming, outgoing) = (layer.previous(k), k);
            // "previous" and "next" follow the request's point order, whatever the travel.
            let (previous, next) = if request_order { (incoming, outgoing) } else { (outgoing, incoming) };
            let (length_previous, length_next) = (layer.lengths[previous], layer.lengths[next]);
            let along = match edge {
                TboneEdge::Longer if length_next > length_previous => next,
                TboneEdge::Shorter if length_next < length_previous => next,
                // Ties go to the previous edge, so the choice never depends on the direction.
                TboneEdge::Longer | TboneEdge::Shorter | TboneEdge::Previous => previous,
                TboneEdge::Next => next,
            };
            ReliefShape { style, target: vertex + offset * layer.air_normal(along), along_edge: Some(along) }
        }
        Relief::Dogbone | Relief::None => {
            let towards_p = (p - vertex).try_normalize(0.0).unwrap_or_else(|| layer.air_normal(k));
            ReliefShape { style: Relief::Dogbone, target: vertex + offset * towards_p, along_edge: None }
        }
    }
}
