//! The capability seam (engineering.md, "The capability seam"; docs/spec/api.md): one trait that every capability
//! implements and every way in dispatches through: the HTTP handlers, the job executor, `kerf
//! run` and the job workers. A capability declares its name, its request and answer types, the
//! tool and machine it refers to, how it solves a resolved request and how it writes its program.
//!
//! The server resolves references (a tool number, a machine name, a material name) once, with
//! [`resolve`], into a
//! [`Resolved`] context; the solver never sees an unresolved reference.

use std::sync::atomic::{AtomicU64, Ordering};

use serde::Serialize;
use serde::de::DeserializeOwned;

pub use crate::control::Control;
use crate::error::SolverError;
use crate::error_code::ErrorCode;
use crate::gcode::{Arcs, Dialect, Post, Reference, ToolCall};
use crate::machine::MachineProfile;
use crate::material::Material;
use crate::tool::{Tool, ToolRef};
pub use crate::units::{Scale, Scaling, Units};

/// One capability: deburr, segment, contour, engagement, predict.
pub trait Capability {
    /// Its name: the endpoint (`/api/v1/{NAME}`), the job `operation` and the page's view id.
    const NAME: &'static str;
    /// How its endpoint is documented; the server generates the endpoint from the registry.
    const ENDPOINT: Endpoint;
    /// The request, as its endpoint takes it and as a job operation holds it.
    type Request: Serialize + DeserializeOwned + Clone + Send + Sync + 'static;
    /// The answer, as its endpoint returns it as JSON and as a job stores it.
    type Answer: Serialize + Send + 'static;
    /// What the capability needs of a tool: [`Tool`] when it always cuts with one, `Option<Tool>`
    /// when the request may name none.
    type Tool: ToolNeed;

    /// The tool, machine and material the request refers to.
    fn refs(request: &Self::Request) -> Refs<'_>;

    /// Tools the request names besides `refs().tool` (deburr's `inner_tool`), each with its
    /// field; resolved like `tool` into [`Resolved::other_tools`], in this order. Default none.
    fn other_tools(_request: &Self::Request) -> Vec<OtherTool<'_>> {
        Vec::new()
    }

    /// Checks the output options before any work, so a program that cannot be written is refused
    /// at once instead of after the computation.
    ///
    /// # Errors
    /// `E_INPUT` naming the option.
    fn check_output(_request: &Self::Request, _output: &OutputOptions) -> Result<(), SolverError> {
        Ok(())
    }

    /// Sets in the request what `output` chooses of the program where the request has its own
    /// say in it (engagement's `?candidate=` over its `candidate`), before a solve whose answer is
    /// that program: the solve then verifies the program that is written, and its header carries
    /// that program's own findings. Default: nothing to set.
    fn set_programmed(_request: &mut Self::Request, _output: &OutputOptions) {}

    /// Solves the request in its resolved context.
    ///
    /// # Errors
    /// The capability's refusals, each with its code and the field at fault.
    fn solve(
        request: &Self::Request,
        context: Resolved<Self::Tool>,
        run: &Run<'_>,
    ) -> Result<Self::Answer, SolverError>;

    /// Writes the G-code program of a solved request, checking `control` as the solve does (a
    /// program of millions of moves takes seconds to write).
    ///
    /// # Errors
    /// When the answer has no program (e.g. `E_NO_PROGRAM`) or an option does not apply;
    /// `E_CANCELLED` once `control`'s cancel flag is set.
    fn program(
        request: &Self::Request,
        answer: &Self::Answer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError>;

    /// The stock as the capability's own verification cuts it (docs/spec/verify.md §9.4): the
    /// program the answer writes with the default output options (Fanuc), its moves on lines up to
    /// `upto_line` (every line: `None`), cut on the capability's model, as binary glTF coloured by
    /// deviation from the model's part, its positions and lengths in `units` (the request's, as its
    /// answer). `None` when the request has no model (verification turned off, or a request or
    /// capability without one). Default `None`.
    ///
    /// # Errors
    /// The solve's refusals; `E_TOO_LARGE_ANSWER` at `verification.resolution` for a mesh over the
    /// answer budget.
    fn cut_stock(
        _request: &Self::Request,
        _context: Resolved<Self::Tool>,
        _upto_line: Option<usize>,
        _units: Units,
        _run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        Ok(None)
    }

    /// Asks [`Self::cut_stock`] at dexel spacing `resolution` (in the request's units) instead of
    /// the request's own: its `verification.resolution` (verify's `resolution`). Default: nothing
    /// to set, for a capability that cuts no stock.
    fn set_cut_resolution(_request: &mut Self::Request, _resolution: f64) {}

    /// The program the request gives to be cut (verify's `program`), whose lines
    /// [`Self::cut_stock`]'s `upto_line` and the findings count; `None` (the default) when the
    /// program cut is the one the answer writes with the default output options (Fanuc).
    fn given_program(_request: &Self::Request) -> Option<&str> {
        None
    }

    /// The units the request says it is written in (its `units`), if it says.
    fn units(_request: &Self::Request) -> Option<Units> {
        None
    }

    /// Converts every length and feed of the request by `scaling` (from its units into mm),
    /// before it is resolved and solved.
    ///
    /// # Errors
    /// `E_INPUT` at `units` for a capability whose requests are read in millimetres only.
    fn scale_request(_request: &mut Self::Request, _scaling: Scaling) -> Result<(), SolverError> {
        Err(SolverError::input(
            "units",
            format!("{} requests are read in mm only (also when their machine's `units` is inch): send mm", Self::NAME),
        ))
    }

    /// Converts every length and feed of the answer by `scaling` (from mm into the request's
    /// units), after its program is written from the answer in mm.
    fn scale_answer(_answer: &mut Self::Answer, _scaling: Scaling) {}

    /// The machine the answer was computed for (its dialect is the program's default).
    fn machine(answer: &Self::Answer) -> Option<&MachineProfile>;

    /// Trims an answer before a job stores it (the program, written before, keeps everything).
    fn for_storage(_answer: &mut Self::Answer) {}

    /// Records how long the solve took, for capabilities whose answer reports it.
    fn record_time(_answer: &mut Self::Answer, _seconds: f64) {}

    /// An upper bound on the bytes the answer takes in memory for `purpose` (the answer built,
    /// its JSON, its program, or for a job both), known before solving from the request's counts
    /// and the solver's own caps; `None` when the capability gives none. An answer whose bound
    /// fits [`AnswerBudget::limit`] is built without counting; the others are counted as they are
    /// built ([`AnswerBudget::charge`]) and refused with `E_TOO_LARGE_ANSWER` when over.
    fn answer_bound(_request: &Self::Request, _context: &Resolved<Self::Tool>, _purpose: Purpose) -> Option<u64> {
        None
    }

    /// The answer as its endpoint's JSON: `serde_json::to_vec`, or the same bytes written faster
    /// (engagement, whose samples are most of a large answer).
    ///
    /// # Errors
    /// When the answer cannot be serialised.
    fn to_json(answer: Self::Answer) -> serde_json::Result<Vec<u8>> {
        serde_json::to_vec(&answer)
    }

    /// Splits the request's work into parts that different workers may solve at once (a job
    /// split into chunks): ranges of its units of work (prediction passes, candidate
    /// paths) sized after `sizing`, each solved by [`Capability::solve_part`], then merged by
    /// [`Capability::finish`] into the answer [`Capability::solve`] gives. `None` (the default):
    /// the request is solved whole, as when it is refused (solving it whole reports why) or too
    /// small to be worth splitting.
    fn split(_request: &Self::Request, _context: &Resolved<Self::Tool>, _sizing: &Sizing) -> Option<Split> {
        None
    }

    /// Solves part `part` of a request [`Capability::split`] split, handing what the finish step
    /// needs to `sink` (the caller stores it, in any serde format, until the finish step).
    ///
    /// # Errors
    /// The capability's refusals, as [`Capability::solve`]; `E_INTERNAL` for a capability that
    /// does not split.
    fn solve_part(
        _request: &Self::Request,
        _context: Resolved<Self::Tool>,
        _part: &Part,
        _run: &Run<'_>,
        _sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        Err(not_split(Self::NAME))
    }

    /// The finish step of a split request: reads the parts' outputs from `parts`, in the order
    /// [`Capability::split`] gave the parts, and gives the answer [`Capability::solve`] would
    /// give for the whole request, equal field for field (its program then byte for byte).
    ///
    /// # Errors
    /// As [`Capability::solve`]; `E_INTERNAL` when the parts do not belong to the request.
    fn finish(
        _request: &Self::Request,
        _context: Resolved<Self::Tool>,
        _parts: &mut impl PartSource,
        _run: &Run<'_>,
    ) -> Result<Self::Answer, SolverError> {
        Err(not_split(Self::NAME))
    }
}

/// How large the parts of a split request should be (see [`Capability::split`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sizing {
    /// The work one part should hold, in seconds of one core of the reference machine (the
    /// capabilities' cost models are measured on it; docs/guide/performance.md, "Split cost models").
    pub part_seconds: f64,
    /// The most parts one request is split into.
    pub max_parts: usize,
}

/// A request split into parts.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// The parts, in order: their units together are the request's, each once.
    pub parts: Vec<Part>,
    /// The estimated work of the finish step, core-seconds.
    pub finish_seconds: f64,
}

impl Split {
    /// `units` cut into parts of about `sizing.part_seconds` each, given the work of one unit and
    /// the fixed work every part repeats (reading the request); `None` when one part would do.
    /// Parts are at least `10 × setup_seconds` long, so the repeated setup stays under a tenth.
    #[must_use]
    pub fn even(
        units: std::ops::Range<usize>,
        unit_seconds: f64,
        setup_seconds: f64,
        finish_seconds: f64,
        sizing: &Sizing,
    ) -> Option<Self> {
        let count = units.len();
        let total = count as f64 * unit_seconds;
        let per_part = sizing.part_seconds.max(10.0 * setup_seconds);
        if !(total.is_finite() && per_part > 0.0) {
            return None;
        }
        let parts = ((total / per_part).round() as usize).clamp(1, sizing.max_parts.max(1)).min(count);
        if parts < 2 {
            return None;
        }
        let parts = (0..parts)
            .map(|k| {
                let from = units.start + count * k / parts;
                let to = units.start + count * (k + 1) / parts;
                Part { units: from..to, seconds: (to - from) as f64 * unit_seconds + setup_seconds }
            })
            .collect();
        Some(Self { parts, finish_seconds })
    }
}

/// One part of a split request: a range of its units of work.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The units, `[start, end)` (passes, candidate paths).
    pub units: std::ops::Range<usize>,
    /// The estimated work, core-seconds.
    pub seconds: f64,
}

/// Where a part's output goes ([`Capability::solve_part`]).
pub trait PartSink {
    /// Stores `value` as the part's output.
    ///
    /// # Errors
    /// `E_INTERNAL` when it cannot be written.
    fn put<T: Serialize>(&mut self, value: &T) -> Result<(), SolverError>;
}

/// The stored outputs of a split request's parts, in order ([`Capability::finish`]).
pub trait PartSource {
    /// How many parts there are.
    fn count(&self) -> usize;

    /// The next part's output, read as `T`; `None` after the last.
    ///
    /// # Errors
    /// `E_INTERNAL` when it cannot be read as `T`.
    fn next_part<T: DeserializeOwned>(&mut self) -> Option<Result<T, SolverError>>;
}

fn not_split(name: &str) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("{name} requests are not split into parts"))
}

/// The documentation of a capability's endpoint `POST /api/v1/{NAME}` in the OpenAPI document.
/// It lives with the capability because the capability knows what it answers and refuses; the
/// server's handler is generated and only forwards these texts.
#[derive(Debug, Clone, Copy)]
pub struct Endpoint {
    /// The one-line summary.
    pub summary: &'static str,
    /// What the endpoint returns, in a paragraph or two.
    pub description: &'static str,
    /// What a 404 means here (which references the request can make).
    pub not_found: &'static str,
    /// What a 422 means here: the capability's refusal codes.
    pub refused: &'static str,
}

/// The references a request makes, to be resolved before it is solved.
#[derive(Debug, Clone, Copy, Default)]
pub struct Refs<'a> {
    /// The tool: a number in the tool table or the tool itself.
    pub tool: Option<&'a ToolRef>,
    /// The name of a registered machine.
    pub machine: Option<&'a str>,
    /// The name of a work material in the materials library.
    pub material: Option<&'a str>,
}

/// A tool a request names besides `tool` (deburr's `inner_tool`): the request field that holds
/// it and the reference. An unknown number is reported at `field`, as `tool` is.
#[derive(Debug, Clone, Copy)]
pub struct OtherTool<'a> {
    /// The request field (`inner_tool`).
    pub field: &'static str,
    /// A number in the tool table or the tool itself.
    pub tool: &'a ToolRef,
}

impl<'a> OtherTool<'a> {
    /// This tool's reference alone, for a lookup that fetches what [`Refs`] name.
    pub fn refs(self) -> Refs<'a> {
        Refs { tool: Some(self.tool), ..Refs::default() }
    }
}

/// Where resolution finds what a request refers to: the tool table, machines registry and
/// materials library (the server's store), or a job's own tools, machines and materials.
pub trait Lookup {
    /// The tool with `number`, if any.
    fn tool(&self, number: u32) -> Option<Tool>;
    /// The machine called `name`, if any.
    fn machine(&self, name: &str) -> Option<MachineProfile>;
    /// The material called `name`, if any.
    fn material(&self, name: &str) -> Option<Material>;
    /// The units of a request that does not say its own, before its machine's (a job file's
    /// `units`); default none.
    fn units(&self) -> Option<Units> {
        None
    }
}

/// A request's references, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved<T> {
    /// The tool ([`Tool`] or `Option<Tool>`, as the capability needs).
    pub tool: T,
    /// The machine the request names, if any.
    pub machine: Option<MachineProfile>,
    /// The work material the request names, if any.
    pub material: Option<Material>,
    /// The tools of [`Capability::other_tools`], in its order (empty for most capabilities).
    pub other_tools: Vec<Tool>,
}

/// How a capability's tool need is met by what resolution found.
pub trait ToolNeed: Sized + Send + 'static {
    /// The tool as the capability takes it, or `None` when the need is not met.
    fn from_found(found: Option<Tool>) -> Option<Self>;
}

impl ToolNeed for Tool {
    fn from_found(found: Option<Tool>) -> Option<Self> {
        found
    }
}

impl ToolNeed for Option<Tool> {
    fn from_found(found: Option<Tool>) -> Option<Self> {
        Some(found)
    }
}

/// Why a reference could not be resolved: the field and what is missing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unresolved {
    /// The request field that refers to it (`tool`, `machine`, `material`).
    pub field: &'static str,
    /// What is missing.
    pub message: String,
}

/// The one resolution step: the tool, machine and material `refs` names, from `lookup`. Inline
/// tools are taken as given (the capability validates them).
///
/// # Errors
/// [`Unresolved`] naming the field of an unknown tool number, machine name or material name.
pub fn resolve<T: ToolNeed>(refs: Refs<'_>, lookup: &impl Lookup) -> Result<Resolved<T>, Unresolved> {
    let found =
        match refs.tool {
            None => None,
            Some(ToolRef::Inline(tool)) => Some(tool.clone()),
            Some(ToolRef::Number(number)) => Some(lookup.tool(*number).ok_or_else(|| Unresolved {
                field: "tool",
                message: format!("tool {number} is not in the tool table"),
            })?),
        };
    let tool =
        T::from_found(found).ok_or_else(|| Unresolved { field: "tool", message: "a tool is needed".to_owned() })?;
    let machine = match refs.machine {
        None => None,
        Some(name) => Some(lookup.machine(name).ok_or_else(|| Unresolved {
            field: "machine",
            message: format!("machine {name:?} is not registered (GET /api/v1/machines)"),
        })?),
    };
    let material = match refs.material {
        None => None,
        Some(name) => Some(lookup.material(name).ok_or_else(|| Unresolved {
            field: "material",
            message: format!("material {name:?} is not in the materials library (GET /api/v1/materials)"),
        })?),
    };
    Ok(Resolved { tool, machine, material, other_tools: Vec::new() })
}

/// The tools `others` name, from `lookup` (inline tools as given), in order.
///
/// # Errors
/// [`Unresolved`] at the other tool's field for an unknown tool number.
pub fn resolve_other_tools(others: &[OtherTool<'_>], lookup: &impl Lookup) -> Result<Vec<Tool>, Unresolved> {
    others
        .iter()
        .map(|other| match other.tool {
            ToolRef::Inline(tool) => Ok(tool.clone()),
            ToolRef::Number(number) => lookup.tool(*number).ok_or_else(|| Unresolved {
                field: other.field,
                message: format!("tool {number} ({}) is not in the tool table", other.field),
            }),
        })
        .collect()
}

/// The one resolution step of capability `C`'s request: [`resolve`] of its [`Capability::refs`]
/// and its [`Capability::other_tools`].
///
/// # Errors
/// As [`resolve`] and [`resolve_other_tools`].
pub fn resolve_request<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
) -> Result<Resolved<C::Tool>, Unresolved> {
    let mut resolved = resolve(C::refs(request), lookup)?;
    resolved.other_tools = resolve_other_tools(&C::other_tools(request), lookup)?;
    Ok(resolved)
}

/// Every reference of capability `C`'s request, for a lookup to fetch: its [`Capability::refs`],
/// then one per other tool.
pub fn all_refs<C: Capability>(request: &C::Request) -> Vec<Refs<'_>> {
    std::iter::once(C::refs(request)).chain(C::other_tools(request).into_iter().map(OtherTool::refs)).collect()
}

/// The units of capability `C`'s request: its own `units`, else the lookup's (a job file's), else
/// those of the machine it names (found in `lookup`), else mm.
pub fn units_of<C: Capability>(request: &C::Request, lookup: &impl Lookup) -> Units {
    C::units(request)
        .or_else(|| lookup.units())
        .or_else(|| C::refs(request).machine.and_then(|name| lookup.machine(name)).and_then(|machine| machine.units))
        .unwrap_or_default()
}

/// Capability `C`'s request in mm, as the solver reads it: `request` itself when it is in mm,
/// else a copy with every length and feed converted from `units`.
///
/// # Errors
/// As [`Capability::scale_request`].
pub fn request_in_mm<C: Capability>(
    request: &C::Request,
    units: Units,
) -> Result<std::borrow::Cow<'_, C::Request>, SolverError> {
    match units.into_mm() {
        None => Ok(std::borrow::Cow::Borrowed(request)),
        Some(scaling) => {
            let mut request = request.clone();
            C::scale_request(&mut request, scaling)?;
            Ok(std::borrow::Cow::Owned(request))
        }
    }
}

/// What the answer is for: limits differ between a JSON answer, a program and a stored job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Purpose {
    /// A JSON answer to a request.
    #[default]
    Json,
    /// A G-code program answering a request.
    Program,
    /// A job: the program and a stored JSON result.
    Job,
}

/// How a solve runs: progress and cancellation, an uploaded file, what the answer is for and the
/// bytes it may take.
#[derive(Debug, Clone, Copy, Default)]
pub struct Run<'a> {
    /// Progress and cancellation.
    pub control: Control<'a>,
    /// A file uploaded with the request (predict's STL stock), if any.
    pub upload: Option<&'a [u8]>,
    /// What the answer is for.
    pub purpose: Purpose,
    /// The bytes the answer may take while it is built; `None`: no limit.
    pub budget: Option<&'a AnswerBudget>,
}

impl Run<'_> {
    /// Charges `bytes` of the answer, built for unit `done` of `total` (a loop of several), to
    /// the budget, if there is one.
    ///
    /// # Errors
    /// `E_TOO_LARGE_ANSWER` when the answer built so far is over the budget's limit.
    pub fn charge(&self, bytes: u64, done: usize, total: usize) -> Result<(), SolverError> {
        self.budget.map_or(Ok(()), |budget| budget.charge(bytes, done, total))
    }

    /// [`AnswerBudget::charge_unit`] on the budget, if there is one (without one the unit's bytes
    /// are not counted).
    ///
    /// # Errors
    /// `E_TOO_LARGE_ANSWER` when the answer built so far is over the budget's limit.
    pub fn charge_unit(
        &self,
        done: usize,
        total: usize,
        answer_bytes: u64,
        unit_bytes: impl FnOnce() -> u64,
    ) -> Result<(), SolverError> {
        self.budget.map_or(Ok(()), |budget| budget.charge_unit(done, total, answer_bytes, unit_bytes))
    }
}

/// The bytes one answer may take while it is built (the answer in memory and its JSON or
/// program), and what it has taken so far. The solver charges its units (a deburr loop) as they
/// are built, so an answer over the limit is refused after at most one unit past it instead of
/// being built whole.
#[derive(Debug)]
pub struct AnswerBudget {
    limit: u64,
    used: AtomicU64,
}

impl AnswerBudget {
    /// A budget of `limit` bytes, none used.
    #[must_use]
    pub fn new(limit: u64) -> Self {
        Self { limit, used: AtomicU64::new(0) }
    }

    /// The limit, bytes.
    #[must_use]
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// The bytes charged so far.
    #[must_use]
    pub fn used(&self) -> u64 {
        self.used.load(Ordering::Relaxed)
    }

    /// Charges `bytes` built for unit `done` (1-based) of `total`; over the limit, the answer is
    /// refused with the estimate of the whole: what was built so far, extrapolated to every unit.
    ///
    /// # Errors
    /// `E_TOO_LARGE_ANSWER` with the estimate and the limit.
    pub fn charge(&self, bytes: u64, done: usize, total: usize) -> Result<(), SolverError> {
        let used = self.used.fetch_add(bytes, Ordering::Relaxed).saturating_add(bytes);
        if used <= self.limit {
            return Ok(());
        }
        let done = done.clamp(1, total.max(1));
        let estimate = (u128::from(used) * total.max(1) as u128 / done as u128).min(u128::from(u64::MAX));
        Err(too_large_answer(u64::try_from(estimate).unwrap_or(u64::MAX), self.limit))
    }

    /// Charges unit `done` (1-based) of `total` as it is built: `unit_bytes()`, and with the first
    /// unit `answer_bytes`, what the answer holds besides its units (tool, machine, summary).
    /// The unit's bytes are counted only here, as counting its JSON writes it.
    ///
    /// # Errors
    /// As [`AnswerBudget::charge`].
    pub fn charge_unit(
        &self,
        done: usize,
        total: usize,
        answer_bytes: u64,
        unit_bytes: impl FnOnce() -> u64,
    ) -> Result<(), SolverError> {
        let extra = if done == 1 { answer_bytes } else { 0 };
        self.charge(unit_bytes() + extra, done, total)
    }

    /// Checks an answer whose whole size is known (its JSON, its program).
    ///
    /// # Errors
    /// `E_TOO_LARGE_ANSWER` when `bytes` is over the limit.
    pub fn check(&self, bytes: u64) -> Result<(), SolverError> {
        if bytes <= self.limit { Ok(()) } else { Err(too_large_answer(bytes, self.limit)) }
    }
}

/// The bytes `value` takes as JSON, counted as it is written (nothing is kept): what a unit of an
/// answer is charged for its JSON ([`AnswerBudget::charge`]).
pub fn json_bytes<T: Serialize + ?Sized>(value: &T) -> u64 {
    let mut counter = ByteCounter(0);
    // Written to a counter, the JSON cannot fail for want of room: count what was written.
    let _ = serde_json::to_writer(&mut counter, value);
    counter.0
}

/// Counts the bytes written to it.
struct ByteCounter(u64);

impl std::io::Write for ByteCounter {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0 += bytes.len() as u64;
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The refusal of an answer estimated at `estimate` bytes under a limit of `limit`.
#[must_use]
pub fn too_large_answer(estimate: u64, limit: u64) -> SolverError {
    const MIB: f64 = 1024.0 * 1024.0;
    SolverError::new(
        ErrorCode::TooLargeAnswer,
        format!(
            "the answer would take about {estimate} bytes ({:.1} MiB), over the limit of {limit} bytes ({:.1} MiB) \
             for one answer: ask for less (a coarser tolerance, fewer holes or samples) or split the request",
            estimate as f64 / MIB,
            limit as f64 / MIB,
        ),
    )
}

/// How a program is written: the caller's choices; what is left open takes the capability's or
/// the machine's default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OutputOptions {
    /// Dialect; `None`: the machine's, else Fanuc.
    pub dialect: Option<Dialect>,
    /// Programmed point; `None`: the capability's default (the tool tip; predict's G-code path
    /// keeps its own).
    pub reference: Option<Reference>,
    /// Which candidate path to program (engagement `paths`); `None`: the request's choice, else 0.
    pub candidate: Option<usize>,
    /// Circular moves as G02/G03 or chords; `None`: the machine's `arcs`, else chords.
    pub arcs: Option<Arcs>,
    /// The program's units (G20 or G21; the request's); `None`: mm.
    pub units: Option<Units>,
}

impl OutputOptions {
    /// The dialect of the program: the one asked for, else the machine's, else Fanuc.
    pub fn dialect_for(&self, machine: Option<&MachineProfile>) -> Dialect {
        self.dialect.or(machine.map(|m| m.dialect)).unwrap_or_default()
    }

    /// How arcs are written: as asked, else the machine's default, else chords.
    pub fn arcs_for(&self, machine: Option<&MachineProfile>) -> Arcs {
        self.arcs.or(machine.and_then(|m| m.arcs)).unwrap_or_default()
    }

    /// The post for a program cut with `tool` on `machine`: these options' dialect and arcs
    /// (else the machine's) and programmed point (else the tool tip).
    pub fn post(&self, machine: Option<&MachineProfile>, tool: &Tool) -> Post {
        Post {
            dialect: self.dialect_for(machine),
            reference: self.reference.unwrap_or_default(),
            tool: ToolCall::for_tool(tool),
            arcs: self.arcs_for(machine),
            plunge_feed: tool.plunge_feed.or(machine.and_then(|m| m.plunge_feed)),
            units: self.units.unwrap_or_default(),
        }
    }
}

/// The program of a solved request with its output options, the dialect defaulting to the
/// machine's: the one way every caller writes a capability's program, under `control` (the
/// run's, so a cancelled request stops writing too).
///
/// # Errors
/// As [`Capability::program`].
pub fn program<C: Capability>(
    request: &C::Request,
    answer: &C::Answer,
    output: &OutputOptions,
    control: Control<'_>,
) -> Result<String, SolverError> {
    control.check()?;
    let machine = C::machine(answer);
    // No dialect asked and no machine: each capability's own default (Fanuc; resegment keeps the
    // program's post).
    let output = OutputOptions {
        dialect: output.dialect.or(machine.map(|m| m.dialect)),
        arcs: Some(output.arcs_for(machine)),
        ..*output
    };
    let text = C::program(request, answer, &output, control)?;
    let dialect = output.dialect.unwrap_or_default();
    let text = crate::gcode::with_haas_smoothing(text, dialect, machine.and_then(|m| m.haas_smoothing));
    if dialect == Dialect::Fanuc || !text.contains(" AT LINE ") {
        return Ok(text);
    }
    // The verification's warnings name lines of the Fanuc program it cut (the default output
    // options, `verify::own::program`), here in this program's units and reference so that the
    // same moves print the same: their lines are this program's own once matched.
    let verified = OutputOptions {
        dialect: Some(Dialect::Fanuc),
        units: output.units,
        reference: output.reference,
        ..OutputOptions::default()
    };
    let verified = program::<C>(request, answer, &verified, control)?;
    Ok(crate::gcode::renumber::warnings_in_own_lines(text, &verified))
}
