//! The materials library: work materials with their Kienzle values, keyed by name,
//! seeded by migration 0006 with published values.

use crate::store::CommitChecked;
use kerf_solver::material::{IsoGroup, Material};

use super::on;
use super::tools::WRITE_ATTEMPTS;
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

/// All materials ordered by name.
pub async fn list(db: &Db) -> AppResult<Vec<Material>> {
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT name, kc11, mc, radial_ratio, iso_group, description FROM materials ORDER BY name",
        [], fetch_all)?;
    rows.into_iter().map(decode).collect()
}

/// Stores `material` (whose `name` is set) whole, replacing any earlier record, if `guard` accepts
/// the material stored under its name now (`None`: none is), and says whether it was new. The
/// read, the guard and the write are one transaction, so no other write falls between what the
/// guard saw and what is written.
pub async fn put(db: &Db, material: &Material, guard: impl Fn(Option<&Material>) -> AppResult<()>) -> AppResult<bool> {
    let name = material.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("material without name")))?;
    let (kc11, mc, radial_ratio, description) =
        (material.kc11, material.mc, material.radial_ratio, material.description.as_deref());
    let iso_group = material.iso_group.map(group_letter);
    macro_rules! put_in {
        ($begin:expr, $select:expr, $update:expr) => {{
            let mut transaction = $begin.await?;
            let mut attempts = 0;
            let created = loop {
                let row: Option<Row> = sqlx::query_as($select).bind(name).fetch_optional(&mut *transaction).await?;
                let current = row.map(decode).transpose()?;
                guard(current.as_ref())?;
                if current.is_some() {
                    sqlx::query($update)
                        .bind(name).bind(kc11).bind(mc).bind(radial_ratio).bind(iso_group).bind(description)
                        .execute(&mut *transaction).await?;
                    break false;
                }
                let inserted = sqlx::query(
                    "INSERT INTO materials (name, kc11, mc, radial_ratio, iso_group, description) VALUES ($1, $2, $3, $4, $5, $6)
                     ON CONFLICT (name) DO NOTHING",
                )
                .bind(name).bind(kc11).bind(mc).bind(radial_ratio).bind(iso_group).bind(description)
                .execute(&mut *transaction).await?;
                if inserted.rows_affected() == 1 {
                    break true;
                }
                // Another writer stored the name after the read: read it again and guard that.
                attempts += 1;
                if attempts == WRITE_ATTEMPTS {
                    return Err(AppError::Conflict(format!("material {name:?} was written concurrently; try again")));
                }
            };
            transaction.commit_checked().await?;
            Ok(created)
        }};
    }
    match db {
        // IMMEDIATE: the write lock from the read on, so no writer comes between.
        Db::Sqlite(pool) => put_in!(
            pool.begin_with("BEGIN IMMEDIATE"),
            SELECT_ONE,
            "UPDATE materials SET kc11 = $2, mc = $3, radial_ratio = $4, iso_group = $5, description = $6,
                 revision = revision + 1, updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE name = $1"
        ),
        // FOR UPDATE holds the row until the commit; a name not stored yet is claimed by the
        // INSERT, which waits for a concurrent one and then does nothing.
        Db::Postgres(pool) => put_in!(
            pool.begin(),
            concat!(select_one!(), " FOR UPDATE"),
            "UPDATE materials SET kc11 = $2, mc = $3, radial_ratio = $4, iso_group = $5, description = $6,
                 revision = revision + 1, updated_at = now() WHERE name = $1"
        ),
    }
}

/// Deletes the material if `guard` accepts the material stored now (`None`: none is), in one
/// transaction; false if there was none.
pub async fn delete(db: &Db, name: &str, guard: impl Fn(Option<&Material>) -> AppResult<()>) -> AppResult<bool> {
    macro_rules! delete_in {
        ($begin:expr, $select:expr) => {{
            let mut transaction = $begin.await?;
            let row: Option<Row> = sqlx::query_as($select).bind(name).fetch_optional(&mut *transaction).await?;
            let current = row.map(decode).transpose()?;
            guard(current.as_ref())?;
            let deleted =
                sqlx::query("DELETE FROM materials WHERE name = $1").bind(name).execute(&mut *transaction).await?;
            transaction.commit_checked().await?;
            Ok(deleted.rows_affected() > 0)
        }};
    }
    match db {
        Db::Sqlite(pool) => delete_in!(pool.begin_with("BEGIN IMMEDIATE"), SELECT_ONE),
        Db::Postgres(pool) => delete_in!(pool.begin(), concat!(select_one!(), " FOR UPDATE")),
    }
}
