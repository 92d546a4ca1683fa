//! The verify request as the client sends it (docs/spec/verify.md §1 Request): the program, the
//! tools it calls, the stock and optionally the part, and the simulation's settings.

use serde::de::{self, Deserializer};
use serde::{Deserialize, Serialize};

use crate::error::SolverError;
use crate::stock::Stock;
use crate::tool::ToolRef;

/// Most tools one request may name.
pub const MAX_TOOLS: usize = 100;

/// A verify request: cut `program` with `tools` out of `stock` and compare with `part`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct VerifyRequest {
    /// The G-code program, as kerf's reader takes it (docs/guide/gcode.md): G0–G3, G17–G19,
    /// G20/G21, G90/G91; at most 2 000 000 lines.
    pub program: String,
    /// The tools the program calls (1–100): a number in the tool table, or a tool given inline
    /// whose `number` is the `T` word that calls it. One tool without a number cuts every move.
    pub tools: Vec<ToolRef>,
    /// The stock before the program: `box`, `cylinder`, `tube` or `grid` (with `bottom`).
    pub stock: Solid,
    /// The part (the design) the program should leave, same kinds as `stock`: with it the answer
    /// reports gouges and material left; without it only the stock and the tools are checked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part: Option<Solid>,
    /// Dexel spacing, mm (> 0): the distance between neighbouring rays of the stock model.
    /// Default: a twentieth of the smallest cutter radius, coarsened so the grid holds at most
    /// 4 000 000 rays. A spacing whose grid would exceed the memory limit is refused
    /// (`E_GRID_MEMORY`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<f64>,
    /// Material removed inside the part deeper than this (mm, along the dexel ray) is a gouge.
    /// Default 0.01.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Material left outside the part thicker than this (mm, along the dexel ray) is reported.
    /// Default 0.1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub allowance: Option<f64>,
    /// A program whose feed moves cut air for more than this share of the cutting time gets an
    /// `air_cutting` finding (0–1). Default 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub air_share_limit: Option<f64>,
    /// Skip blocks starting with `/` (the block-delete switch on). Default false.
    #[serde(default)]
    pub block_delete: bool,
    /// The work material, by name in the materials library: with it every block that cuts gets
    /// the spindle power its removal rate needs (from the material's Kienzle values at the
    /// block's feed per tooth; the program must set a spindle speed, `S`, before it cuts).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// A registered machine, by name (needs `material`): a block needing more spindle power than
    /// the machine has at the block's spindle speed (`spindle_power_kw`, lowered to its power
    /// curve) is a `spindle_power` finding.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// `mm` (default, or the machine's) or `inch`: the units of every length of the request and
    /// the answer (volumes stay in the mm³ their names say), and of `mesh` solids' STL files
    /// unless their `units` says otherwise (docs/spec/api.md, Units). The program keeps its own
    /// G20/G21.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
}

/// A solid of the stock or the part: predict's stock kinds (docs/spec/predict.md §1.2), or a tube.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(as = VerifySolid))]
#[serde(untagged)]
pub enum Solid {
    /// A hollow cylinder.
    Tube(Hollow),
    /// Box, cylinder, grid (needs `bottom` here), as predict takes them, or `mesh`: a closed,
    /// outward-oriented STL file uploaded with the request (form part `part` or `stock`); `plane`
    /// is refused (no bottom).
    Stock(Stock),
}

/// A hollow solid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Hollow {
    /// A tube between two points of its axis: the material between `inner_radius` and
    /// `outer_radius` from the axis.
    Tube {
        /// One end of the axis, mm.
        start: [f64; 3],
        /// The other end of the axis, mm.
        end: [f64; 3],
        /// Outer radius, mm.
        outer_radius: f64,
        /// Inner radius (the bore), mm; 0 < inner_radius < outer_radius.
        inner_radius: f64,
        /// Cross holes drilled through it (at most 100), each a cylinder between two points of
        /// its axis: the material within `radius` of that segment is taken away. Default none.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        holes: Vec<CrossHole>,
    },
}

/// Most cross holes of one tube.
pub const MAX_CROSS_HOLES: usize = 100;

/// A cross hole of a tube: a cylinder between two points of its axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CrossHole {
    /// One end of the hole's axis, mm.
    pub start: [f64; 3],
    /// The other end of the hole's axis, mm.
    pub end: [f64; 3],
    /// The hole's radius, mm (> 0).
    pub radius: f64,
}

/// The STL files of a request's `mesh` solids as the capability takes them, in one upload (the
/// run's): the one file when one solid is a mesh; when both are, the part's file's length as 8
/// bytes (little-endian), the part's file, then the stock's ([`Meshes::pack`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Meshes<'a> {
    /// The part's STL file.
    pub part: Option<&'a [u8]>,
    /// The stock's STL file.
    pub stock: Option<&'a [u8]>,
}

impl Solid {
    /// Whether the solid is an uploaded mesh.
    pub fn is_mesh(&self) -> bool {
        matches!(self, Self::Stock(Stock::Mesh { .. }))
    }
}

impl<'a> Meshes<'a> {
    /// The one upload holding the part's and the stock's files.
    pub fn pack(part: &[u8], stock: &[u8]) -> Vec<u8> {
        let mut upload = Vec::with_capacity(8 + part.len() + stock.len());
        upload.extend_from_slice(&(part.len() as u64).to_le_bytes());
        upload.extend_from_slice(part);
        upload.extend_from_slice(stock);
        upload
    }

    /// The files of `upload` for `request`'s mesh solids.
    ///
    /// # Errors
    /// `E_INPUT` at `part.kind` for an upload when no solid is a mesh, at `body` for an upload
    /// holding both files that is not laid out as [`Meshes::pack`] lays it out.
    pub fn unpack(request: &VerifyRequest, upload: Option<&'a [u8]>) -> Result<Self, SolverError> {
        let part_mesh = request.part.as_ref().is_some_and(Solid::is_mesh);
        match (part_mesh, request.stock.is_mesh(), upload) {
            (_, _, None) => Ok(Self::default()),
            (true, true, Some(both)) => {
                let length = both
                    .get(..8)
                    .and_then(|prefix| usize::try_from(u64::from_le_bytes(prefix.try_into().ok()?)).ok())
                    .filter(|length| length.checked_add(8).is_some_and(|end| end <= both.len()))
                    .ok_or_else(|| {
                        SolverError::input("body", "the upload does not hold the part's and the stock's files")
                    })?;
                let (part, stock) = both[8..].split_at(length);
                Ok(Self { part: Some(part), stock: Some(stock) })
            }
            (true, false, Some(part)) => Ok(Self { part: Some(part), stock: None }),
            (false, true, Some(stock)) => Ok(Self { part: None, stock: Some(stock) }),
            (false, false, Some(_)) => Err(SolverError::input(
                "part.kind",
                "an STL file was uploaded but neither part.kind nor stock.kind is \"mesh\"",
            )),
        }
    }
}

// By the `kind` field: `tube` is read as [`Hollow`], every other kind as predict's [`Stock`], so a
// bad field is reported by the type that has it (an untagged enum would only say that nothing
// matched).
impl<'de> Deserialize<'de> for Solid {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let value = serde_json::Value::deserialize(deserializer)?;
        if value.get("kind").and_then(serde_json::Value::as_str) == Some("tube") {
            serde_json::from_value(value).map(Solid::Tube).map_err(de::Error::custom)
        } else {
            serde_json::from_value(value).map(Solid::Stock).map_err(de::Error::custom)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solids_read_by_kind() {
        let tube: Solid = serde_json::from_str(
            r#"{"kind": "tube", "start": [0, 0, 0], "end": [0, 0, 10], "outer_radius": 5, "inner_radius": 3}"#,
        )
        .unwrap();
        assert!(matches!(tube, Solid::Tube(Hollow::Tube { .. })));
        let block: Solid = serde_json::from_str(r#"{"kind": "box", "min": [0, 0, 0], "max": [1, 1, 1]}"#).unwrap();
        assert!(matches!(block, Solid::Stock(Stock::Box { .. })));
        let round = serde_json::to_string(&tube).unwrap();
        assert_eq!(serde_json::from_str::<Solid>(&round).unwrap(), tube);
        let bad = serde_json::from_str::<Solid>(r#"{"kind": "tube", "start": [0, 0, 0]}"#).unwrap_err();
        assert!(bad.to_string().contains("end"), "{bad}");
        assert!(serde_json::from_str::<Solid>(r#"{"kind": "cone"}"#).is_err());
    }
}
