//! Work materials (docs/spec/engagement.md §11 item 4): the Kienzle values of a named material, as
//! the materials library stores them (`/api/v1/materials/{name}`) and as an engagement request
//! names them with `material`. The server resolves the name; the solver only sees the values.

use serde::{Deserialize, Serialize};

use crate::engagement::Kienzle;
use crate::error::SolverError;

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
