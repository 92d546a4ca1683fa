//! The materials library: work materials with their Kienzle values, keyed by name,
//! seeded by migration 0006 with published values.

use kerf_solver::material::{IsoGroup, Material};

use super::on;
use crate::db::Db;
use crate::error::{AppError, AppResult};

/// One row: name, k_c1.1, m_c, F_r/F_t, ISO group, description.
type Row = (String, f64, f64, Option<f64>, Option<String>, Option<String>);

fn group_letter(group: IsoGroup) -> &'static str {
    match group {
        IsoGroup::P => "P",
        IsoGroup::M => "M",
        IsoGroup::K => "K",
        IsoGroup::N => "N",
        IsoGroup::S => "S",
        IsoGroup::H => "H",
    }
}

fn decode((name, kc11, mc, radial_ratio, iso_group, description): Row) -> AppResult<Material> {
    let iso_group = iso_group
        .map(|letter| {
            serde_json::from_value(serde_json::Value::String(letter))
                .map_err(|error| AppError::Internal(anyhow::anyhow!("stored material {name:?} is unreadable: {error}")))
        })
        .transpose()?;
    Ok(Material { name: Some(name), kc11, mc, radial_ratio, iso_group, description })
}

/// The material called `name`, if stored.
pub async fn get(db: &Db, name: &str) -> AppResult<Option<Material>> {
    let row: Option<Row> = on!(db, query_as,
        both: "SELECT name, kc11, mc, radial_ratio, iso_group, description FROM materials WHERE name = $1",
        [name], fetch_optional)?;
    row.map(decode).transpose()
}

/// All materials ordered by name.
pub async fn list(db: &Db) -> AppResult<Vec<Material>> {
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT name, kc11, mc, radial_ratio, iso_group, description FROM materials ORDER BY name",
        [], fetch_all)?;
    rows.into_iter().map(decode).collect()
}

/// Stores `material` (whose `name` is set) whole, replacing any earlier record, and says whether
/// it was new.
pub async fn put(db: &Db, material: &Material) -> AppResult<bool> {
    let name = material.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("material without name")))?;
    let (revision,): (i64,) = on!(db, query_as,
        sqlite: "INSERT INTO materials (name, kc11, mc, radial_ratio, iso_group, description) VALUES ($1, $2, $3, $4, $5, $6)
         ON CONFLICT (name) DO UPDATE SET kc11 = excluded.kc11, mc = excluded.mc, radial_ratio = excluded.radial_ratio,
             iso_group = excluded.iso_group, description = excluded.description, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')
         RETURNING revision",
        postgres: "INSERT INTO materials (name, kc11, mc, radial_ratio, iso_group, description) VALUES ($1, $2, $3, $4, $5, $6)
         ON CONFLICT (name) DO UPDATE SET kc11 = excluded.kc11, mc = excluded.mc, radial_ratio = excluded.radial_ratio,
             iso_group = excluded.iso_group, description = excluded.description, revision = materials.revision + 1,
             updated_at = now()
         RETURNING revision",
        [name, material.kc11, material.mc, material.radial_ratio, material.iso_group.map(group_letter),
         material.description.as_deref()],
        fetch_one)?;
    Ok(revision == 1)
}

/// Deletes the material; false if there was none.
pub async fn delete(db: &Db, name: &str) -> AppResult<bool> {
    let result = on!(db, query, both: "DELETE FROM materials WHERE name = $1", [name], execute)?;
    Ok(result > 0)
}
