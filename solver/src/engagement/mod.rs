//! Tool–workpiece engagement over time and flute-count recommendation (spec: docs/spec/engagement.md;
//! patent 003).
//!
//! The tool's cutting circle moves along a 2-D tool-centre path over a plan-view stock. At each
//! sample the solver finds the engaged arcs (angles of the circle touching material not yet
//! removed, in the tool-angle convention of §4.1: 90° ahead, 0° right, 180° left of travel),
//! and derives the radial depth, entry/exit angles, milling mode and burr/chipping flags, the
//! summed chip thickness of k teeth maximised exactly over the tooth phase, the representative
//! values and machining time per flute count, and the flute counts that meet a thickness and a
//! time limit. Beyond the patent it returns the feed that holds a target chip thickness (per block
//! and as G-code), the removal rate over time, and compares several candidate paths at once.
//!
//! * [`request`]: the request and its validation (§2, §9);
//! * `segments`: the path of lines and arcs and its sampling (§5.2);
//! * `stock`, `outline`, `bbox_tree`: the material W₀ and the indexes over it and the path (the
//!   plane geometry itself is [`crate::planar`]'s);
//! * `exact`: engine B, the exact boundary test (§5.3.3, default);
//! * `dots`: engine A, the patent's dot removal (§5.3.2);
//! * `arcs`: arc merging, a_e and the per-arc quantities (§5.4, §5.5, §5.10);
//! * `teeth`: H_k and n_k with the exact phase maximisation (§5.6);
//! * `contact`: each sample's contact from the chosen engine;
//! * `evaluate`, `diagnostics`: one path end to end, and its warnings (§5, §9);
//! * `flutes`: representative values, time, recommendation (§5.7–§5.9);
//! * `feed`: chip-thinning feed plan (§11 item 3), capped by the spindle's power and torque;
//! * `kienzle`, `force`: Kienzle's law (its values are the work material's,
//!   [`crate::material::Kienzle`]), spindle torque and power with the helix lag (§11 items 4, 5);
//!   `heights`: a ball or bull end's engagement by height;
//! * `arcfeed`: the arc-feed correction of the chip thickness on curved paths (§11 item 6);
//! * `phase`: the phase maximum of a general per-tooth load;
//! * `limits`: the tooth-passing frequency against the tool's natural frequencies (§11 item 9);
//!   the spindle's ratings it checks the torque against are the machine's
//!   ([`crate::machine::SpindleLimits`], §11 item 4);
//! * [`program()`]: G-code with the planned F words.
//!
//! Choices where the spec is open (§13): `cw` rotation by default; constant f_z when
//! `feed_per_tooth` is given, constant V_f when `feed` is; statistics over the engaged samples
//! (m ≥ 1, not a plunge, not a rapid), the mean weighted by sample spacing; machining time over
//! feed moves only; θ in degrees; the contact graph is 2-D, the full radius's (the axial depth,
//! the helix and a rounded end's smaller sections enter only the forces). A
//! path that never touches the stock is not an error: the answer is all zeros with
//! `W_NO_CONTACT` (§9). The exact engine splits the circle at its exact boundary crossings
//! instead of stepping θ, so it has no angle step and its arc ends are exact.
//!
//! Cutting physics (§11 items 4–6, 9; only with `kienzle` or `material`, so answers without
//! them are unchanged): every tooth cuts a chip a_p wide with a straight edge, or on a ball or
//! bull end a chip f_z·sin θ·sin κ thin and dz/sin κ wide at the lever arm r(z), integrated over
//! the height in bands, each with the engaged arcs of its own section (radius r(z)) against the
//! stock its height has left (engine `exact`; engine `dots` takes the full radius's arcs at
//! every height, with `W_FORCE_MODEL`); a_p is `axial_depth`, or `stock_top_z` less the path's
//! Z (`cut_z`, a G-code path's own); the spindle limits are compared with the torque
//! averaged over the tooth phase, the load the drive carries (its rotor's inertia smooths the
//! tooth-by-tooth peaks), while the peaks over the phase are reported for the tool; the
//! tooth-passing frequency is compared with the fundamental only.
//!
//! A path may also be G-code text (`{"gcode": "..."}`), read by the shared
//! [`crate::gcode::reader`]: its XY moves, lines and arcs, from the first known position on.

mod answer;
mod arcfeed;
mod arcs;
mod bbox_tree;
mod capability;
mod contact;
mod diagnostics;
mod dots;
mod evaluate;
mod exact;
mod feed;
mod flutes;
mod force;
mod heights;
mod job;
mod kienzle;
mod limits;
mod outline;
mod phase;
pub mod program;
pub use job::Physics;
pub mod request;
mod segments;
mod series;
mod stock;
mod teeth;
mod units;
mod wire;

pub use crate::geometry::Direction;
pub use answer::{
    ArcDetail, Comparison, EngagementSample, EngagementSolution, FeedBlock, FeedLimit, FeedPlan, FluteLimit,
    FluteResult, ForceInfo, GridInfo, OverLimit, PathEngagement, SampleFlag,
};
pub use arcs::{MillingMode, SpindleDirection};
pub use capability::{EngagementAnswer, EngagementCapability};
pub use limits::RESONANCE_BAND;
pub use program::program;
pub use request::{
    Candidate, EngagementRequest, Engine, FeedBasis, FeedPlanRequest, PathInput, PathSegments, PreviousCut,
    Representative, SegmentInput, Stock, StockBitmap, StockPolygon,
};

use crate::capability::Control;
use crate::error::SolverError;
use crate::machine::MachineProfile;
use crate::tool::Tool;

/// A point or vector in the plane, mm.
pub(crate) type P2 = nalgebra::Vector2<f64>;

/// Most candidate paths in one request.
pub const MAX_CANDIDATES: usize = 16;
/// Largest flute count, and most flute counts in one request.
pub const MAX_FLUTES: u32 = 32;
/// Most dots of the `dots` engine's grid (and cells of a bitmap stock): 10⁹ bits = 125 MB.
pub const MAX_GRID_DOTS: u64 = 1_000_000_000;
/// Most grid rows the `dots` engine may scan over a request (samples × rows across the tool;
/// about 25 s of work), refused past it with `E_WORK_LIMIT`.
pub const MAX_DOT_ROWS: f64 = 5e8;
/// Most chords when arcs are written as lines (the G-code program; earlier cuts in the dots
/// engine).
pub const MAX_CHORDS: f64 = 1e7;
/// Most samples over all candidate paths of one request.
pub const MAX_SAMPLES: usize = 200_000;
/// Most segments (or points) of one path.
pub const MAX_SEGMENTS: usize = 100_000;
/// Most vertices of a polygon stock, all rings together.
pub const MAX_STOCK_VERTICES: usize = 100_000;
/// Most contact dots returned for the scatter plot; more are decimated.
pub const MAX_CONTACT_DOTS: usize = 1_000_000;
/// Most bitmap cell-edge tests of the exact engine over a request (about 8R/cell per sample).
pub(crate) const MAX_BITMAP_CROSSINGS: f64 = 2e9;
/// ψ_B default, degrees (§5.10).
pub const DEFAULT_BURR_DISENGAGE_DEG: f64 = 80.0;
/// ψ_C default, degrees (§5.10).
pub const DEFAULT_CHIPPING_DISENGAGE_DEG: f64 = 20.0;

/// Solves an engagement request with its resolved tool: one result for `path`, the candidates
/// side by side for `paths`.
///
/// # Errors
/// `E_INPUT` naming the field for bad numbers; `E_PATH` (empty path, arc centre not equidistant),
/// `E_STOCK` (crossing or degenerate rings, bad bitmap), `E_TOO_LARGE`, `E_TOO_MANY_SAMPLES`,
/// `E_GRID_MEMORY` (limits, with the limit in the message), `E_WORK_LIMIT`.
pub fn solve(request: &EngagementRequest, tool: &Tool) -> Result<EngagementSolution, SolverError> {
    solve_with(request, tool, None)
}

/// [`solve`] for a request that names a machine: `machine` is the profile its `machine` names
/// (its `max_feed` fills an absent `feed_plan.max_feed` and lowers a larger one, with
/// `W_FEED_ABOVE_MACHINE_MAX`; no flute count over its max feed or spindle speed is recommended).
///
/// # Errors
/// As [`solve`]. `machine` is the profile the request's `machine` names, resolved by the caller
/// (`capability::resolve`).
pub fn solve_with(
    request: &EngagementRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
) -> Result<EngagementSolution, SolverError> {
    solve_in(request, tool, machine, &Physics::default(), Control::default())
}

/// [`solve_with`] with what the server resolved for the cutting physics: the Kienzle values of
/// the request's `material` and the machine's spindle limits (docs/spec/engagement.md §11 item 4). The
/// limits are checked only when the request gives `kienzle` or `material`.
///
/// # Errors
/// As [`solve_with`]; `E_INPUT` at `material` when the request names a material and
/// `physics.material` is absent, at `axial_depth` when forces are asked for without it, and for
/// bad Kienzle values or limits; `E_CANCELLED` once `control`'s cancel flag is set (checked per
/// sample).
pub fn solve_in(
    request: &EngagementRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    physics: &Physics,
    control: Control<'_>,
) -> Result<EngagementSolution, SolverError> {
    let job = request.validate(tool, machine, physics)?;
    let mut results = Vec::with_capacity(job.candidates.len());
    for (index, candidate) in job.candidates.iter().enumerate() {
        let mut result =
            control.part(index, job.candidates.len(), |part| evaluate::evaluate(&job, candidate, tool, part))?;
        if let Some((blocks, warnings)) = program::blocks(&result, control)? {
            result.blocks = Some(blocks);
            result.warnings.extend(warnings);
        }
        results.push(result);
    }
    if job.single
        && let Some(result) = results.pop()
    {
        return Ok(EngagementSolution::Single(Box::new(result)));
    }
    Ok(EngagementSolution::Comparison(Comparison { candidates: results }))
}
