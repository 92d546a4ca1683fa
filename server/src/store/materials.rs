//! The materials library: work materials with their Kienzle values, keyed by name,
//! seeded by migration 0006 with published values.

use kerf_solver::material::{IsoGroup, Material};

use super::{Bind, Registry, guarded_delete, guarded_put, on};
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

/// The row of the material `$1`: a macro so PostgreSQL's `FOR UPDATE` can be appended with `concat!`.
macro_rules! select_one {
    () => {
        "SELECT name, kc11, mc, radial_ratio, iso_group, description FROM materials WHERE name = $1"
    };
}
const SELECT_ONE: &str = select_one!();

/// The material called `name`, if stored.
pub async fn get(db: &Db, name: &str) -> AppResult<Option<Material>> {
    let row: Option<Row> = on!(db, query_as, both: SELECT_ONE, [name], fetch_optional)?;
    row.map(decode).transpose()
}

/// Up to `limit` materials named after `after` (all when `None`), ordered by name.
pub async fn list(db: &Db, after: Option<&str>, limit: i64) -> AppResult<Vec<Material>> {
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT name, kc11, mc, radial_ratio, iso_group, description FROM materials
               WHERE $1 IS NULL OR name > $1 ORDER BY name LIMIT $2",
        [after, limit], fetch_all)?;
    rows.into_iter().map(decode).collect()
}

/// The statements of the materials library's guarded writes.
fn registry(name: &str) -> Registry {
    Registry {
        item: format!("material {name:?}"),
        select_sqlite: SELECT_ONE,
        select_postgres: concat!(select_one!(), " FOR UPDATE"),
        update_sqlite: "UPDATE materials SET kc11 = $2, mc = $3, radial_ratio = $4, iso_group = $5, description = $6,
             revision = revision + 1, updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE name = $1",
        update_postgres: "UPDATE materials SET kc11 = $2, mc = $3, radial_ratio = $4, iso_group = $5, description = $6,
             revision = revision + 1, updated_at = now() WHERE name = $1",
        insert: "INSERT INTO materials (name, kc11, mc, radial_ratio, iso_group, description) VALUES ($1, $2, $3, $4, $5, $6)
             ON CONFLICT (name) DO NOTHING",
        delete: "DELETE FROM materials WHERE name = $1",
    }
}

/// Stores `material` (whose `name` is set) whole, replacing any earlier record, if `guard` accepts
/// the material stored under its name now (`None`: none is), and says whether it was new
/// (`guarded_put`).
pub async fn put(db: &Db, material: &Material, guard: impl Fn(Option<&Material>) -> AppResult<()>) -> AppResult<bool> {
    let name = material.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("material without name")))?;
    let values = [
        Bind::Real(material.kc11),
        Bind::Real(material.mc),
        Bind::OptionalReal(material.radial_ratio),
        Bind::OptionalText(material.iso_group.map(group_letter)),
        Bind::OptionalText(material.description.as_deref()),
    ];
    guarded_put(db, &registry(name), Bind::Text(name), &values, decode, guard).await
}

/// Deletes the material if `guard` accepts the material stored now (`None`: none is), in one
/// transaction; false if there was none.
pub async fn delete(db: &Db, name: &str, guard: impl Fn(Option<&Material>) -> AppResult<()>) -> AppResult<bool> {
    guarded_delete(db, &registry(name), Bind::Text(name), decode, guard).await
}
