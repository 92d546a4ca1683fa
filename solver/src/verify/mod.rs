//! Verifying a program by cutting it (docs/spec/verify.md): a material-removal simulation of the
//! stock as z-dexels, swept by the tool assembly along the program's G0–G3 moves as kerf's reader
//! reads them, compared with the part.
//!
//! [`request`] holds the wire types, `job` their validation, `solid` the stock and part on the
//! grid, `dexel` the rays, `assembly` the tool's bodies, `sweep` a body swept along a move,
//! `simulate` the cutting and its findings (whole, or by strips of the grid's rows for a job split
//! among workers), `mesh` the cut stock as binary glTF, `capability` the seam's entry, and [`own`]
//! the verification of the programs the other capabilities write, on their own models.

mod assembly;
mod capability;
pub(crate) mod dexel;
mod job;
mod mesh;
pub mod own;
pub mod request;
pub(crate) mod simulate;
mod solid;
mod sweep;
#[cfg(test)]
pub(crate) mod tests;
mod units;

pub use assembly::{FLUTE_RADII, HOLDER_LENGTH, HOLDER_SHANK_DIAMETERS, Member, STICKOUT_RADII};
pub use capability::{VerifyAnswer, VerifyCapability};
pub use job::{
    DEFAULT_AIR_SHARE_LIMIT, DEFAULT_ALLOWANCE, DEFAULT_RESOLUTION_RADII, DEFAULT_TOLERANCE, Found, MAX_DEFAULT_RAYS,
    MAX_DEXEL_BYTES,
};
pub use mesh::{GLB_MEDIA_TYPE, GOUGE_COLOUR, LEFT_COLOUR, NEUTRAL_COLOUR, cut_stock_glb};
pub use own::{Verification, VerificationOptions};
pub use request::{CrossHole, Hollow, MAX_CROSS_HOLES, Meshes, Solid, VerifyRequest};
pub use simulate::{ARC_CHORD_TOLERANCE, BlockRemoval, Cut, Finding, FindingKind, MAX_FINDINGS};

use crate::capability::Run;
use crate::error::SolverError;
use crate::tool::Tool;

/// Cuts `request`'s program with its resolved `tools` (in the order of `request.tools`) and the
/// material and machine it names (`found`).
///
/// # Errors
/// As the capability's solve: the request's refusals, each naming its field.
pub fn verify(request: &VerifyRequest, tools: &[Tool], found: Found<'_>, run: &Run<'_>) -> Result<Cut, SolverError> {
    let job = request.validate(tools, found, run.upload, run.control)?;
    simulate::cut(&job, run)
}
