//! The capability registry: the one list of kerf's capabilities (the seam of engineering.md,
//! `kerf_solver::capability`). From it come the job `Operation` enum with its names, reading and
//! dispatch, and the names the page and the OpenAPI document list. HTTP handlers, the job
//! executor, `kerf run` and the workers all solve through [`solve`] here.

use std::borrow::Cow;
use std::time::Instant;

use kerf_solver::SolverError;
use kerf_solver::capability::{
    self, Capability, Lookup, OutputOptions, Part, PartSink, PartSource, Refs, Resolved, Run, Sizing, Split, ToolNeed,
    Units,
};
use kerf_solver::machine::MachineProfile;
use kerf_solver::material::Material;
use kerf_solver::tool::{Tool, ToolRef};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use utoipa::ToSchema;

use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::store;

/// The registry: the one list of capabilities, one entry each. It hands the list to `$callback`
/// (a macro in scope where it is called): [`registry!`] here builds the job [`Operation`] from it,
/// `http::endpoints` the HTTP endpoints. An entry names the variant of [`Operation`]; the solver
/// module with the capability, request and answer types (named so the OpenAPI document shows the
/// concrete schemas; the compiler checks that they are the capability's); the endpoint's body,
/// `json(Query)` with the query parameters it takes (a type of `http::output`), `drawing(Query)` for
/// JSON or a form with a DXF file (`http::dxf::Submitted`), or `upload` for a capability with its
/// own handler in `http/<module>.rs` (which also routes its program, if it writes one: verify
/// answers findings only); and the operation's description.
macro_rules! with_registry {
    ($callback:ident) => {
        $callback! {
            Deburr => deburr::{DeburrCapability, DeburrRequest, DeburrAnswer}, json(OutputQuery),
                "`POST /api/v1/deburr`.";
            Segment => segment::{SegmentCapability, SegmentRequest, SegmentAnswer}, drawing(OutputQuery),
                "`POST /api/v1/segment`.";
            Resegment => segment::{ResegmentCapability, ResegmentRequest, ResegmentAnswer}, json(OutputQuery),
                "`POST /api/v1/resegment`: a G-code program's feed moves cut again by the block-time rule.";
            Contour => contour::{ContourCapability, ContourRequest, ContourAnswer}, drawing(OutputQuery),
                "`POST /api/v1/contour`.";
            Engagement => engagement::{EngagementCapability, EngagementRequest, EngagementAnswer}, json(CandidateQuery),
                "`POST /api/v1/engagement`; the job's program is that of the request's `candidate` path (default the first).";
            Predict => predict::{PredictCapability, PredictRequest, PredictAnswer}, upload,
                "`POST /api/v1/predict` (a job file cannot carry an STL file: no `mesh` stock).";
            Verify => verify::{VerifyCapability, VerifyRequest, VerifyAnswer}, upload,
                "`POST /api/v1/verify`: its findings, no program (a job file cannot carry an STL file: no `mesh` part or stock).";
        }
    };
}
pub(crate) use with_registry;

/// Builds the job [`Operation`] and its dispatch from the registry's entries.
macro_rules! registry {
    ($($variant:ident => $module:ident::{$capability:ident, $request:ident, $answer:ident}, $body:ident $(($query:ident))?, $doc:literal;)+) => {
        $(
            use kerf_solver::$module::{$capability, $request};
            const _: fn(<$capability as Capability>::Request) -> $request = |request| request;
            const _: fn(<$capability as Capability>::Answer) -> kerf_solver::$module::$answer = |answer| answer;
        )+

        /// One job operation: `operation` names the capability, the other fields are its
        /// endpoint's request.
        #[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
        #[serde(tag = "operation", rename_all = "snake_case")]
        #[allow(clippy::large_enum_variant, reason = "a job holds at most 100 operations, read once")]
        pub enum Operation {
            $(
                #[doc = $doc]
                $variant($request),
            )+
        }

        /// Every capability's name, in registry order: endpoints, job operations, page views.
        pub const NAMES: &[&str] = &[$(<$capability as Capability>::NAME),+];

        impl Operation {
            /// The capability's name (`deburr`, ...).
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(_) => <$capability as Capability>::NAME,)+
                }
            }

            /// The tool, machine and material the operation refers to.
            pub fn refs(&self) -> Refs<'_> {
                match self {
                    $(Self::$variant(request) => <$capability as Capability>::refs(request),)+
                }
            }

            /// The units the operation is written in: its `units`, else its machine's from
            /// `lookup`, else mm.
            pub fn units(&self, lookup: &impl Lookup) -> Units {
                match self {
                    $(Self::$variant(request) => capability::units_of::<$capability>(request, lookup),)+
                }
            }

            /// Every reference of the operation, for a lookup to fetch: its [`Self::refs`], then
            /// one per further tool (deburr's `inner_tool`).
            pub fn all_refs(&self) -> Vec<Refs<'_>> {
                match self {
                    $(Self::$variant(request) => capability::all_refs::<$capability>(request),)+
                }
            }

            /// Checks that the operation's references resolve against `lookup`.
            ///
            /// # Errors
            /// The 404 naming the field of an unknown tool, machine or material.
            pub fn check_refs(&self, lookup: &impl Lookup) -> Result<(), AppError> {
                match self {
                    $(Self::$variant(request) => resolve::<$capability>(request, lookup).map(drop),)+
                }
            }

            /// Solves the operation as a job does: resolved against `lookup`, its program written
            /// with `output`, its answer trimmed for storage.
            ///
            /// # Errors
            /// The problem of the refusal (cancellation is `E_CANCELLED`).
            pub fn run(&self, lookup: &impl Lookup, run: &Run<'_>, output: &OutputOptions) -> Result<Stored, AppError> {
                match self {
                    $(Self::$variant(request) => store_output::<$capability>(request, lookup, run, output),)+
                }
            }

            /// How the operation divides into parts that different workers solve at once
            /// ([`Capability::split`]), resolved against `lookup`; `None`: it is solved whole.
            pub fn split(&self, lookup: &impl Lookup, sizing: &Sizing) -> Option<Split> {
                match self {
                    $(Self::$variant(request) => split::<$capability>(request, lookup, sizing),)+
                }
            }

            /// Solves part `part` of the operation as a job does; its output, serialised for the
            /// finish step.
            ///
            /// # Errors
            /// The problem of the refusal (cancellation is `E_CANCELLED`).
            pub fn run_part(&self, lookup: &impl Lookup, part: &Part, run: &Run<'_>) -> Result<PartBytes, AppError> {
                match self {
                    $(Self::$variant(request) => part_output::<$capability>(request, lookup, part, run),)+
                }
            }

            /// The finish step of a split operation: merges its parts' outputs (`parts`, in
            /// order) into what [`Operation::run`] stores for the whole operation. `seconds` is
            /// what the parts' solves took, for the answers that report their time.
            ///
            /// # Errors
            /// The problem of the refusal (cancellation is `E_CANCELLED`).
            pub fn finish(
                &self,
                lookup: &impl Lookup,
                parts: &mut impl PartSource,
                run: &Run<'_>,
                output: &OutputOptions,
                seconds: f64,
            ) -> Result<Stored, AppError> {
                match self {
                    $(Self::$variant(request) => {
                        finish_output::<$capability>(request, lookup, parts, run, output, seconds)
                    })+
                }
            }

            /// The stock as the operation's program cut it ([`cut_stock`]), resolved against
            /// `lookup`: GLB in the operation's units.
            ///
            /// # Errors
            /// As [`cut_stock`].
            pub fn cut_stock(&self, lookup: &impl Lookup, ask: StockAsk, run: &Run<'_>) -> Result<Vec<u8>, AppError> {
                match self {
                    $(Self::$variant(request) => cut_stock::<$capability>(request, lookup, ask, run),)+
                }
            }

            /// The program [`Operation::cut_stock`] cuts ([`cut_program`]), in the operation's
            /// units.
            ///
            /// # Errors
            /// As [`cut_program`].
            pub fn cut_program(&self, lookup: &impl Lookup, run: &Run<'_>) -> Result<String, AppError> {
                match self {
                    $(Self::$variant(request) => cut_program::<$capability>(request, lookup, run),)+
                }
            }

            /// Reads the request of the capability called `name` from `fields`.
            fn read<'de, D: serde::Deserializer<'de>>(name: &str, fields: D) -> Result<Self, D::Error> {
                $(
                    if name == <$capability as Capability>::NAME {
                        return <$request>::deserialize(fields).map(Self::$variant);
                    }
                )+
                Err(serde::de::Error::unknown_variant(name, NAMES))
            }
        }
    };
}

with_registry!(registry);

// Hand-written instead of serde's internally tagged enum, which buffers the table and so loses
// the field path and line of errors inside it. When `operation` is the first key (as in every
// example) the rest of the table is read in place; otherwise it is buffered and dispatched.
impl<'de> Deserialize<'de> for Operation {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct OperationVisitor;

        impl<'de> serde::de::Visitor<'de> for OperationVisitor {
            type Value = Operation;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("an operation table with `operation` and its request's fields")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Operation, A::Error> {
                use serde::de::Error;
                let Some(first) = map.next_key::<String>()? else {
                    return Err(A::Error::missing_field("operation"));
                };
                if first == "operation" {
                    let OperationName(name) = map.next_value()?;
                    return Operation::read(name, serde::de::value::MapAccessDeserializer::new(map));
                }
                let mut fields = serde_json::Map::new();
                fields.insert(first, map.next_value()?);
                while let Some(key) = map.next_key::<String>()? {
                    let value = map.next_value()?;
                    fields.insert(key, value);
                }
                let name = fields.remove("operation").ok_or_else(|| A::Error::missing_field("operation"))?;
                let OperationName(name) = serde_json::from_value(name).map_err(A::Error::custom)?;
                Operation::read(name, serde_json::Value::Object(fields)).map_err(A::Error::custom)
            }
        }

        deserializer.deserialize_map(OperationVisitor)
    }
}

/// The value of `operation`: one of [`NAMES`] (an unknown one is reported at `operation` itself).
struct OperationName(&'static str);

impl<'de> Deserialize<'de> for OperationName {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = String::deserialize(deserializer)?;
        NAMES
            .iter()
            .find(|known| **known == name)
            .map(|known| Self(known))
            .ok_or_else(|| serde::de::Error::unknown_variant(&name, NAMES))
    }
}

/// Tools, machines and materials found for a set of references: what a request or a job refers
/// to, fetched from the store or given in a job file. Resolution looks things up here only.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Catalog {
    /// Tools, each with its number.
    pub tools: Vec<Tool>,
    /// Machines, each with its name.
    pub machines: Vec<MachineProfile>,
    /// Work materials, each with its name.
    pub materials: Vec<Material>,
}

impl Lookup for Catalog {
    fn tool(&self, number: u32) -> Option<Tool> {
        tool_in(&self.tools, number)
    }

    fn machine(&self, name: &str) -> Option<MachineProfile> {
        machine_in(&self.machines, name)
    }

    fn material(&self, name: &str) -> Option<Material> {
        material_in(&self.materials, name)
    }
}

/// `catalog` completed with the tools, machines and materials `refs` name that it lacks, from the
/// tool table, the machines registry and the materials library (those that exist; resolution
/// reports the others).
pub async fn catalog<'a>(
    db: &Db,
    refs: impl IntoIterator<Item = Refs<'a>>,
    mut catalog: Catalog,
) -> AppResult<Catalog> {
    for refs in refs {
        if let Some(ToolRef::Number(number)) = refs.tool
            && !catalog.tools.iter().any(|tool| tool.number == Some(*number))
            && let Some(tool) = store::tools::get(db, *number).await?
        {
            catalog.tools.push(tool);
        }
        if let Some(name) = refs.machine
            && !catalog.machines.iter().any(|machine| machine.name.as_deref() == Some(name))
            && let Some(machine) = store::machines::get(db, name).await?
        {
            catalog.machines.push(MachineProfile { name: Some(name.to_owned()), ..machine });
        }
        if let Some(name) = refs.material
            && !catalog.materials.iter().any(|material| material.name.as_deref() == Some(name))
            && let Some(material) = store::materials::get(db, name).await?
        {
            catalog.materials.push(material);
        }
    }
    Ok(catalog)
}

/// The tool numbered `number` in `tools`.
pub fn tool_in(tools: &[Tool], number: u32) -> Option<Tool> {
    tools.iter().find(|tool| tool.number == Some(number)).cloned()
}

/// The machine called `name` in `machines`.
pub fn machine_in(machines: &[MachineProfile], name: &str) -> Option<MachineProfile> {
    machines.iter().find(|machine| machine.name.as_deref() == Some(name)).cloned()
}

/// The material called `name` in `materials`.
pub fn material_in(materials: &[Material], name: &str) -> Option<Material> {
    materials.iter().find(|material| material.name.as_deref() == Some(name)).cloned()
}

/// The one resolution step, for capability `C`: its request's references from `lookup`.
///
/// # Errors
/// 404 naming `tool`, `machine`, `material` or another tool's field (`inner_tool`) when a
/// reference is unknown.
pub fn resolve<C: Capability>(request: &C::Request, lookup: &impl Lookup) -> Result<Resolved<C::Tool>, AppError> {
    capability::resolve_request::<C>(request, lookup)
        .map_err(|unresolved| AppError::unknown(unresolved.field, unresolved.message))
}

/// [`resolve`] for references outside a capability (the contour loops endpoint).
///
/// # Errors
/// As [`resolve`].
pub fn resolve_refs<T: ToolNeed>(refs: Refs<'_>, lookup: &impl Lookup) -> Result<Resolved<T>, AppError> {
    capability::resolve(refs, lookup).map_err(|unresolved| AppError::unknown(unresolved.field, unresolved.message))
}

/// Capability `C`'s request in mm, as the solver reads it, and the units it was written in (its
/// `units`, else its machine's from `lookup`, else mm): the one conversion of a request at the edge.
///
/// # Errors
/// 422 naming `units` when the capability reads its requests in mm only.
pub fn in_mm<'a, C: Capability>(
    request: &'a C::Request,
    lookup: &impl Lookup,
) -> Result<(Cow<'a, C::Request>, Units), AppError> {
    let units = capability::units_of::<C>(request, lookup);
    Ok((capability::request_in_mm::<C>(request, units)?, units))
}

/// A refusal of a request written in `units`: the solver writes its lengths and feeds in mm, which
/// the message restates in the request's units (`Scaling::restate`).
pub fn refusal_in(error: SolverError, units: Units) -> SolverError {
    let Some(scaling) = units.from_mm() else { return error };
    if error.code() == kerf_solver::ErrorCode::Cancelled {
        return error;
    }
    let converted = SolverError::new(error.code(), scaling.restate(error.message()));
    match error.field() {
        Some(field) => converted.at(field),
        None => converted,
    }
}

/// An answer's JSON object with `units` first.
fn with_units(mut json: Vec<u8>, units: Units) -> Vec<u8> {
    if json.first() == Some(&b'{') {
        let field = format!("\"units\":\"{}\"{}", units.as_str(), if json.get(1) == Some(&b'}') { "" } else { "," });
        json.splice(1..1, field.into_bytes());
    }
    json
}

/// `answer` in `units` (converted from mm), as its endpoint's JSON with `units` echoed.
fn answer_json<C: Capability>(mut answer: C::Answer, units: Units) -> Result<Vec<u8>, AppError> {
    if let Some(scaling) = units.from_mm() {
        C::scale_answer(&mut answer, scaling);
    }
    let bytes = C::to_json(answer).map_err(|error| AppError::Internal(error.into()))?;
    Ok(with_units(bytes, units))
}

/// What a cut-stock request asks besides the capability's request: the last line cut (every
/// line: `None`) and a dexel spacing in place of the request's (in its units).
#[derive(Debug, Clone, Copy, Default)]
pub struct StockAsk {
    /// Cut the moves on lines up to this one (1-based, of the program cut).
    pub upto_line: Option<usize>,
    /// Dexel spacing, in the request's units.
    pub resolution: Option<f64>,
}

/// Capability `C`'s cut stock ([`Capability::cut_stock`]) of `request` resolved against `lookup`:
/// GLB in the request's units. Runs on a blocking thread.
///
/// # Errors
/// As the capability's endpoint: 404 for an unknown reference, 422 for its refusals (restated in
/// the request's units); 422 `E_INPUT` at `verification` when the request has no model to cut
/// (verification turned off, or a capability without one).
pub fn cut_stock<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
    ask: StockAsk,
    run: &Run<'_>,
) -> Result<Vec<u8>, AppError> {
    let mut asked = Cow::Borrowed(request);
    if let Some(resolution) = ask.resolution {
        C::set_cut_resolution(asked.to_mut(), resolution);
    }
    let (request, units) = in_mm::<C>(&asked, lookup)?;
    let request = request.as_ref();
    let resolved = resolve::<C>(request, lookup)?;
    C::cut_stock(request, resolved, ask.upto_line, units, run).map_err(|error| refusal_in(error, units))?.ok_or_else(
        || {
            AppError::from(SolverError::input(
                "verification",
                format!(
                    "this {} request has no model to cut its program on: its verification is turned off, or it has \
                     none (docs/spec/verify.md §9.2)",
                    C::NAME
                ),
            ))
        },
    )
}

/// The program [`cut_stock`] cuts, in the request's units: the one the request gives
/// ([`Capability::given_program`]), else the one its answer writes with the default output
/// options in the Fanuc dialect. Runs on a blocking thread.
///
/// # Errors
/// As [`solve`], and the refusal of a capability that writes no program.
pub fn cut_program<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
    run: &Run<'_>,
) -> Result<String, AppError> {
    if let Some(program) = C::given_program(request) {
        return Ok(program.to_owned());
    }
    let (request, units) = in_mm::<C>(request, lookup)?;
    let request = request.as_ref();
    let resolved = resolve::<C>(request, lookup)?;
    let fanuc = OutputOptions { dialect: Some(kerf_solver::gcode::Dialect::Fanuc), ..OutputOptions::default() };
    match solve::<C>(request, resolved, run, Some(&fanuc), false, units)? {
        (Delivered::Program(program), _) => Ok(program),
        (Delivered::Json(_), _) => Err(AppError::Internal(anyhow::anyhow!("a program was asked for"))),
    }
}

/// What a solve gives its caller: the answer as JSON, or the program.
#[derive(Debug)]
pub enum Delivered {
    /// The JSON answer.
    Json(Vec<u8>),
    /// The G-code program.
    Program(String),
}

/// Solves a resolved request of capability `C` (in mm, [`in_mm`]) and delivers the JSON answer
/// in `units`, or the program in `units` when `program` gives its output options. `timings` adds
/// the solve time to answers that report it. Returns the delivery and the seconds the solve
/// took. Runs on a blocking thread.
///
/// # Errors
/// The solver's refusal, or a failure to serialise.
pub fn solve<C: Capability>(
    request: &C::Request,
    resolved: Resolved<C::Tool>,
    run: &Run<'_>,
    program: Option<&OutputOptions>,
    timings: bool,
    units: Units,
) -> Result<(Delivered, f64), AppError> {
    let run = &counted::<C>(request, &resolved, run);
    let started = Instant::now();
    let mut answer = C::solve(request, resolved, run).map_err(|error| refusal_in(error, units))?;
    let seconds = started.elapsed().as_secs_f64();
    if let Some(output) = program {
        let output = OutputOptions { units: Some(units), ..*output };
        let program = capability::program::<C>(request, &answer, &output, run.control)
            .map_err(|error| refusal_in(error, units))?;
        check_size(run, program.len())?;
        return Ok((Delivered::Program(program), seconds));
    }
    if timings {
        C::record_time(&mut answer, seconds);
    }
    run.control.check()?;
    let bytes = answer_json::<C>(answer, units)?;
    check_size(run, bytes.len())?;
    Ok((Delivered::Json(bytes), seconds))
}

/// `run` with its answer budget only when the capability's bound before solving
/// ([`Capability::answer_bound`]) does not already show that the answer fits it: such an answer
/// is built without counting.
fn counted<'a, C: Capability>(request: &C::Request, resolved: &Resolved<C::Tool>, run: &Run<'a>) -> Run<'a> {
    let budget = run
        .budget
        .filter(|budget| C::answer_bound(request, resolved, run.purpose).is_none_or(|bound| bound > budget.limit()));
    Run { budget, ..*run }
}

/// Refuses a delivered answer (JSON, program, or a job's both) of `bytes` over the run's budget.
fn check_size(run: &Run<'_>, bytes: usize) -> Result<(), AppError> {
    let Some(budget) = run.budget else { return Ok(()) };
    Ok(budget.check(u64::try_from(bytes).unwrap_or(u64::MAX))?)
}

/// One operation's stored output.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct Stored {
    /// The operation's name (`deburr`, ...).
    pub operation: String,
    /// Its answer, exactly as its endpoint answers JSON (kept as text, so served byte for byte).
    #[schema(value_type = Object)]
    pub result: Box<RawValue>,
    /// Its G-code program, when one could be written.
    #[serde(skip)]
    pub gcode: Option<String>,
    /// Why no program could be written, if so.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gcode_problem: Option<String>,
}

fn store_output<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
    run: &Run<'_>,
    output: &OutputOptions,
) -> Result<Stored, AppError> {
    let (request, units) = in_mm::<C>(request, lookup)?;
    let request = request.as_ref();
    let resolved = resolve::<C>(request, lookup)?;
    let run = &counted::<C>(request, &resolved, run);
    let started = Instant::now();
    let mut answer = C::solve(request, resolved, run).map_err(|error| refusal_in(error, units))?;
    C::record_time(&mut answer, started.elapsed().as_secs_f64());
    stored::<C>(request, answer, output, run, units)
}

fn split<C: Capability>(request: &C::Request, lookup: &impl Lookup, sizing: &Sizing) -> Option<Split> {
    let (request, _) = in_mm::<C>(request, lookup).ok()?;
    let resolved = resolve::<C>(&request, lookup).ok()?;
    C::split(&request, &resolved, sizing)
}

/// A part's output, serialised (CBOR: every number exactly as computed, non-finite ones too), and
/// how long its solve took.
#[derive(Debug)]
pub struct PartBytes {
    /// The output.
    pub bytes: Vec<u8>,
    /// Seconds.
    pub seconds: f64,
}

/// Where a part's output goes: CBOR bytes (the job layer compresses and stores them).
#[derive(Debug, Default)]
struct CborSink(Vec<u8>);

impl PartSink for CborSink {
    fn put<T: Serialize>(&mut self, value: &T) -> Result<(), SolverError> {
        self.0.clear();
        ciborium::into_writer(value, &mut self.0).map_err(|error| {
            SolverError::new(kerf_solver::ErrorCode::Internal, format!("a part's output cannot be written: {error}"))
        })
    }
}

fn part_output<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
    part: &Part,
    run: &Run<'_>,
) -> Result<PartBytes, AppError> {
    let (request, units) = in_mm::<C>(request, lookup)?;
    let resolved = resolve::<C>(&request, lookup)?;
    let started = Instant::now();
    let mut sink = CborSink::default();
    C::solve_part(&request, resolved, part, run, &mut sink).map_err(|error| refusal_in(error, units))?;
    Ok(PartBytes { bytes: sink.0, seconds: started.elapsed().as_secs_f64() })
}

fn finish_output<C: Capability>(
    request: &C::Request,
    lookup: &impl Lookup,
    parts: &mut impl PartSource,
    run: &Run<'_>,
    output: &OutputOptions,
    seconds: f64,
) -> Result<Stored, AppError> {
    let (request, units) = in_mm::<C>(request, lookup)?;
    let request = request.as_ref();
    let resolved = resolve::<C>(request, lookup)?;
    let run = &counted::<C>(request, &resolved, run);
    let started = Instant::now();
    let mut answer = C::finish(request, resolved, parts, run).map_err(|error| refusal_in(error, units))?;
    C::record_time(&mut answer, seconds + started.elapsed().as_secs_f64());
    stored::<C>(request, answer, output, run, units)
}

/// A job's stored output of `answer` (in mm): its program written with `output` in `units`, the
/// answer in `units` trimmed for storage; refused when the two are over the run's answer budget.
fn stored<C: Capability>(
    request: &C::Request,
    mut answer: C::Answer,
    output: &OutputOptions,
    run: &Run<'_>,
    units: Units,
) -> Result<Stored, AppError> {
    let output = OutputOptions { units: Some(units), ..*output };
    let program = capability::program::<C>(request, &answer, &output, run.control);
    // A cancelled job stops here rather than storing "cancelled" as the reason it has no program.
    if let Err(error) = &program
        && error.code() == kerf_solver::ErrorCode::Cancelled
    {
        return Err(error.clone().into());
    }
    C::for_storage(&mut answer);
    if let Some(scaling) = units.from_mm() {
        C::scale_answer(&mut answer, scaling);
    }
    let json = with_units(serde_json::to_vec(&answer).map_err(|error| AppError::Internal(error.into()))?, units);
    let result = RawValue::from_string(String::from_utf8(json).map_err(|error| AppError::Internal(error.into()))?)
        .map_err(|error| AppError::Internal(error.into()))?;
    check_size(run, result.get().len() + program.as_ref().map_or(0, String::len))?;
    Ok(Stored {
        operation: C::NAME.to_owned(),
        result,
        // The reason quotes lengths in mm, as every refusal: restated in the operation's units.
        gcode_problem: program.as_ref().err().map(|error: &SolverError| {
            let error = refusal_in(error.clone(), units);
            format!("{} ({})", error.message(), error.code())
        }),
        gcode: program.ok(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_match_the_operation_tags() {
        for name in NAMES {
            let json = serde_json::json!({ "operation": name });
            let error = serde_json::from_value::<Operation>(json).unwrap_err().to_string();
            assert!(!error.contains("unknown variant"), "{name}: {error}");
        }
        assert_eq!(NAMES, ["deburr", "segment", "resegment", "contour", "engagement", "predict", "verify"]);
    }
}
