//! Work materials (docs/spec/engagement.md §11 item 4): Kienzle's cutting-force values
//! ([`Kienzle`], as an engagement request gives them inline with `kienzle`) and the named
//! materials that hold them, as the materials library stores them (`/api/v1/materials/{name}`)
//! and as an engagement request names them with `material`. The server resolves the name; the
//! solver only sees the values.

use serde::{Deserialize, Serialize};

use crate::error::SolverError;
use crate::validate::{Measure, positive_at_most};

/// Kienzle's specific cutting force of a work material (docs/spec/engagement.md §11 item 4): the
/// tangential force on one tooth is `kc11 · a_p · h^(1 − mc)` for a chip of thickness h and
/// width a_p (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Kienzle {
    /// k_c1.1: specific cutting force at h = 1 mm and b = 1 mm, N/mm² (0 < k_c1.1 ≤ 20 000; e.g.
    /// about 2200 for a plain carbon steel, 700 for an aluminium alloy).
    pub kc11: f64,
    /// m_c: Kienzle's exponent (0 ≤ m_c < 1; typically 0.15–0.3).
    pub mc: f64,
    /// F_r/F_t, the radial force of a tooth as a share of its tangential force (≥ 0; default
    /// [`DEFAULT_RADIAL_RATIO`]); it enters only the resultant force on the tool.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_ratio: Option<f64>,
}

/// F_r/F_t when `radial_ratio` is not given: a middle value of the 0.2–0.5 that sharp end mills
/// show; give the measured ratio of the tool and material where it matters.
pub const DEFAULT_RADIAL_RATIO: f64 = 0.3;

/// Largest k_c1.1 accepted, N/mm²: hardened steels reach about 5000; a larger value is a unit
/// mistake (N/m², or MPa at another chip size).
pub const MAX_KC11: f64 = 20_000.0;

impl Kienzle {
    /// Checks the values, naming fields under `prefix` (e.g. `kienzle.`).
    ///
    /// # Errors
    /// `E_INPUT` when `kc11` is not in (0, [`MAX_KC11`]] or `mc` is outside [0, 1).
    pub fn validate(&self, prefix: &str) -> Result<(), SolverError> {
        positive_at_most(&format!("{prefix}kc11"), self.kc11, MAX_KC11, Measure::Number)?;
        if !(self.mc.is_finite() && (0.0..1.0).contains(&self.mc)) {
            return Err(SolverError::input(
                format!("{prefix}mc"),
                format!("mc must be at least 0 and below 1 (got {})", self.mc),
            ));
        }
        if let Some(ratio) = self.radial_ratio
            && !(ratio.is_finite() && (0.0..=10.0).contains(&ratio))
        {
            return Err(SolverError::input(
                format!("{prefix}radial_ratio"),
                format!("radial_ratio must be in [0, 10] (got {ratio})"),
            ));
        }
        Ok(())
    }
}

/// Longest material name (the same rule as machine names).
pub const MAX_NAME_CHARS: usize = 64;
/// Longest description: room for the grade, its condition and the source of the values.
pub const MAX_DESCRIPTION_CHARS: usize = 500;

/// The ISO 513 machinability group of a work material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub enum IsoGroup {
    /// Steel.
    P,
    /// Stainless steel.
    M,
    /// Cast iron.
    K,
    /// Non-ferrous metals (aluminium, copper).
    N,
    /// Heat-resistant super alloys and titanium.
    S,
    /// Hardened steel.
    H,
}

/// A work material of the library: `PUT /api/v1/materials/{name}` stores it; an engagement
/// request with `"material": "name"` cuts it with these Kienzle values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// The name it is stored under (`/api/v1/materials/{name}`; a body may repeat it, and a job
    /// file's `materials` entries need it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// k_c1.1: specific cutting force at h = 1 mm and b = 1 mm, N/mm² (0 < k_c1.1 ≤ 20 000).
    pub kc11: f64,
    /// m_c: Kienzle's exponent (0 ≤ m_c < 1).
    pub mc: f64,
    /// F_r/F_t of a tooth in this material (0–10; default 0.3 in the force model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_ratio: Option<f64>,
    /// ISO 513 group: `P`, `M`, `K`, `N`, `S` or `H`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iso_group: Option<IsoGroup>,
    /// Free text: grade, condition, and where the values come from (at most 500 characters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
}

impl Material {
    /// The Kienzle values the force model takes.
    #[must_use]
    pub fn kienzle(&self) -> Kienzle {
        Kienzle { kc11: self.kc11, mc: self.mc, radial_ratio: self.radial_ratio }
    }

    /// Checks every value, naming the field as written in the material's JSON.
    ///
    /// # Errors
    /// `E_INPUT` for a bad name, Kienzle values out of range or a description too long or with
    /// control characters.
    pub fn validate(&self) -> Result<(), SolverError> {
        if let Some(name) = &self.name {
            validate_material_name(name)?;
        }
        self.kienzle().validate("")?;
        if let Some(description) = &self.description {
            crate::validate::text("description", description, MAX_DESCRIPTION_CHARS)?;
        }
        Ok(())
    }
}

/// Checks a material name for the library path `/api/v1/materials/{name}`: 1–64 characters of
/// letters, digits, `-`, `_` and `.`, not starting with `.` (`C45`, `X5CrNi18-10`, `EN-GJL-250`).
///
/// # Errors
/// `E_INPUT` at `name` otherwise.
pub fn validate_material_name(name: &str) -> Result<(), SolverError> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if name.is_empty() || name.chars().count() > MAX_NAME_CHARS || name.starts_with('.') || !name.chars().all(allowed) {
        return Err(SolverError::input(
            "name",
            format!(
                "a material name has 1 to {MAX_NAME_CHARS} letters, digits, '-', '_' or '.', and does not start with '.'"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn materials_round_trip_and_validate() {
        let json =
            r#"{"name": "C45", "kc11": 2220, "mc": 0.14, "iso_group": "P", "description": "plain carbon steel"}"#;
        let material: Material = serde_json::from_str(json).unwrap();
        material.validate().unwrap();
        assert_eq!(material.kienzle(), Kienzle { kc11: 2220.0, mc: 0.14, radial_ratio: None });
        let text = serde_json::to_string(&material).unwrap();
        assert_eq!(serde_json::from_str::<Material>(&text).unwrap(), material);

        let field = |material: Material| material.validate().unwrap_err().field().map(str::to_owned);
        assert_eq!(field(Material { kc11: 0.0, ..material.clone() }).as_deref(), Some("kc11"));
        assert_eq!(field(Material { kc11: 2.2e9, ..material.clone() }).as_deref(), Some("kc11"));
        assert_eq!(field(Material { mc: 1.0, ..material.clone() }).as_deref(), Some("mc"));
        assert_eq!(field(Material { radial_ratio: Some(-0.1), ..material.clone() }).as_deref(), Some("radial_ratio"));
        assert_eq!(field(Material { name: Some(".x".into()), ..material.clone() }).as_deref(), Some("name"));
        let long = Material { description: Some("x".repeat(501)), ..material.clone() };
        assert_eq!(field(long).as_deref(), Some("description"));
        assert!(serde_json::from_str::<Material>(r#"{"kc11": 1, "mc": 0.2, "iso_group": "Q"}"#).is_err());
    }
}
