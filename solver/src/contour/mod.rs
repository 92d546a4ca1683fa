//! Layered contour milling with sharp protruding corners (spec: docs/spec/contour.md; patent 004, JP5447809B2)
//! and inside-corner relief.
//!
//! At a protruding (convex) corner the tool cuts up to the corner point P of its centre path,
//! runs straight on past it, turns round in the air and comes back through P along the next
//! face, so the control's corner blending can never round the tip (claim 1). Inside corners get
//! an optional dogbone or T-bone relief, and every corner reports the material left or over-cut.
//!
//! * [`request`]: [`ContourRequest`] and its validation (docs/spec/api.md Contour, docs/spec/contour.md §1.4);
//! * `prepare`: closing, duplicates, collinear points, simplicity, orientation (§3.1);
//! * `layer`: one layer's contour in traversal order, corner classification (§3.2), tilted
//!   walls (§3.9.2);
//! * `offset`: the miter CL polygon with edge events (O2–O4, §3.3): edges too short for the
//!   tool next to inside corners (tessellated fillets tighter than the tool) are passed over at
//!   one merged corner point and their material reported, instead of refusing the contour;
//! * `pass`: CL validity (O5, global clearance), corner actions, global gouge check with
//!   fallbacks (§3.5.5), stock contact (§3.5.7);
//! * [`loops`]: arc, triangle and parallelogram loops and their sizing (§3.5.1–3.5.4);
//! * `relief`: dogbone and T-bone reliefs (beyond the patent);
//! * [`material`]: material left and over-cut, control models M1/M2 (§3.10);
//! * `solve`: layers, passes, links at the clearance plane, the answer (§3.8, §3.9.1);
//! * `moves`: one layer's moves: lead point, entry, the passes' chords, links and retract
//!   (§3.9.1);
//! * `report`: the answer's corner, pass and warning reports and the description (§3.8, §3.10);
//! * [`division`]: division coordinates, the one-number encoding and the claim-10 check (§3.6,
//!   §3.7);
//! * [`detect`]: corner detection on an existing CL point list (§3.4, claims 8–9), and loops
//!   added to such a path ([`detect::loop_path`]);
//! * [`program`](mod@program): G-code;
//! * `blocks`: with `block_time_ms`, the block figures of the answer;
//! * `parts`: a job's layers split into ranges that several workers make at once;
//! * `wire`: the answer as JSON, its moves written by hand (the same text as serde's).
//!
//! Choices where the spec is open (see also the module docs):
//! * `direction` `climb` (default) puts the material on the right of travel (σ = −1);
//!   `conventional` is σ = +1, the spec's cases. The contour is always given counter-clockwise;
//!   `side` says whether the material is inside it (`outside`) or outside it (`inside`).
//! * Layers run from `depths.top` down in equal steps of at most `depths.step`, the last at
//!   `depths.bottom`; all passes of a layer are cut before the next layer (§3.9.1).
//! * Every pass starts and ends at S on the start edge; a straight lead along that edge's normal
//!   joins S to a lead point in the air, where the tool plunges (feed) and retracts (rapid) to the
//!   clearance plane between layers.
//! * Arcs (loop arcs, round joins) are chorded from outside (tangent polylines within
//!   `tolerance`), so the tool never cuts inside an arc and the loop's first chord continues the
//!   exit leg exactly.
//! * The stock before the first pass is unknown unless `stock_allowance` is given; loops run at
//!   `loop_feed` only where they provably clear the stock (S1/S2 models), else at `feed`.
//! * Material is reported per corner for ideal execution of the final pass (inside-corner fillets,
//!   relief over-cuts, stretches the tool cannot follow) and, with a `controller` model, as
//!   predicted under blending (M1) and servo lag (M2); convex corners lose nothing ideally.
//! * The effective radius is the tool's `radius` for every kind (its widest part cuts the
//!   vertical wall); ball and bull tools differ only in the G-code reference point.
//! * With `block_time_ms` (docs/spec/segment.md) every arc is chorded at the block-time rule's chord
//!   error for its radius, never coarser than `tolerance`: cutting arcs (round joins) at `feed`,
//!   loop arcs at the larger of `feed` and `loop_feed` (a loop runs at one or the other, and a
//!   block longer than needed never starves the control). An arc too tight for one block keeps
//!   `tolerance` and is reported (`W_INFEASIBLE_FEED_FOR_RADIUS`) instead of refusing the
//!   contour: the loops and joins are kerf's own, not the part's. Straight moves are the part's
//!   edges and stay as they are; `summary.blocks` counts the short ones.

pub mod answer;
mod blocks;
mod capability;
pub mod detect;
pub mod division;
mod element;
mod job;
mod layer;
pub mod loops;
pub mod material;
mod moves;
mod offset;
mod parts;
mod pass;
mod prepare;
pub mod program;
mod relief;
mod report;
pub mod request;
mod solve;
mod units;
mod wire;

pub use answer::{
    ContourCorner, ContourLayer, ContourMove, ContourSolution, ContourSummary, Convexity, CornerAction, LoopReport,
    MaterialReport, MoveKind, PassReport, ReliefReport,
};
pub use capability::{ContourAnswer, ContourCapability, LoopsAnswer, LoopsRequest, MAX_JSON_MOVES};
pub use element::{Element, ElementKind};
pub use pass::{Action, CornerPlan, ElementMeta, PassPlan};
pub use program::program;
pub use relief::ReliefShape;
pub use request::{
    ContourRequest, ControllerModel, CornerLoop, CornerOverride, CutDirection, Depths, Join, LoopStyle, PassSpec,
    Relief, Side, TboneEdge, Tilt,
};
pub use solve::{Plan, plan, solve, solve_with, solve_within};
