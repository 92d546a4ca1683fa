//! The materials library over HTTP: `PUT/GET/DELETE /api/v1/materials/{name}`, list.
//! A material holds Kienzle's k_c1.1 and m_c (docs/spec/engagement.md §11 item 4); an engagement request
//! that names it cuts it with these values.

use axum::Json;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::Response;
use kerf_solver::SolverError;
use kerf_solver::material::{Material, validate_material_name};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::{NamePage, page_limit};
use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppJson, AppPath, AppQuery, DeleteHeaders, Preconditions, ReplaceHeaders, etag_of, tagged};
use crate::state::AppState;
use crate::store;

/// The `{name}` path parameter.
#[derive(Debug, serde::Deserialize)]
struct MaterialName {
    name: String,
}

fn checked_name(MaterialName { name }: MaterialName) -> AppResult<String> {
    validate_material_name(&name)?;
    Ok(name)
}

fn unknown(name: &str) -> AppError {
    AppError::not_found(format!("material {name:?} is not in the materials library"))
}

/// The materials of the library, ordered by name (the seeded ones included), a page at a time
/// with `limit` and `after`.
#[utoipa::path(get, path = "/api/v1/materials", tag = "materials", params(NamePage),
    responses(
        (status = 200, body = Vec<Material>),
        (status = 400, description = "`limit` is not a number from 1 to 1000 (`E_QUERY`, naming it)", body = Problem, content_type = "application/problem+json")))]
async fn list_materials(
    State(state): State<AppState>,
    AppQuery(page): AppQuery<NamePage>,
) -> AppResult<Json<Vec<Material>>> {
    let limit = page_limit(page.limit)?;
    Ok(Json(store::materials::list(&state.db, page.after.as_deref(), limit).await?))
}

/// One material.
#[utoipa::path(get, path = "/api/v1/materials/{name}", tag = "materials",
    params(("name" = String, Path, description = "Material name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$")),
    responses(
        (status = 200, body = Material, headers(("ETag" = String, description = "The stored material's strong entity tag: send it in `If-Match` to replace or delete only this version"))),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name", body = Problem, content_type = "application/problem+json")))]
async fn get_material(State(state): State<AppState>, AppPath(name): AppPath<MaterialName>) -> AppResult<Response> {
    let name = checked_name(name)?;
    let material = store::materials::get(&state.db, &name).await?.ok_or_else(|| unknown(&name))?;
    tagged(StatusCode::OK, &material)
}

/// Stores or replaces a material: 201 when new, 200 when replaced (the record is replaced whole).
/// `If-Match` replaces only the version the client has seen, `If-None-Match: *` only creates;
/// else 412 `E_PRECONDITION_FAILED`.
#[utoipa::path(put, path = "/api/v1/materials/{name}", tag = "materials",
    params(
        ("name" = String, Path, description = "Material name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$"),
        ReplaceHeaders),
    request_body = Material,
    responses(
        (status = 201, description = "Created", body = Material, headers(("ETag" = String, description = "The stored material's strong entity tag"))),
        (status = 200, description = "Replaced", body = Material, headers(("ETag" = String, description = "The stored material's strong entity tag"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` or `If-None-Match` does not hold (`E_PRECONDITION_FAILED`, naming the header); the `ETag` header carries the current tag when the material exists", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name or value", body = Problem, content_type = "application/problem+json")))]
async fn put_material(
    State(state): State<AppState>,
    AppPath(name): AppPath<MaterialName>,
    preconditions: Preconditions,
    AppJson(mut material): AppJson<Material>,
) -> AppResult<Response> {
    let name = checked_name(name)?;
    if material.name.as_ref().is_some_and(|given| *given != name) {
        return Err(SolverError::input("name", format!("body name differs from the path's {name:?}")).into());
    }
    material.name = Some(name);
    material.validate()?;
    let item = format!("material {:?}", material.name.as_deref().unwrap_or_default());
    let created = store::materials::put(&state.db, &material, |current| {
        preconditions.check(&item, current.map(etag_of).transpose()?.as_deref())
    })
    .await?;
    tagged(if created { StatusCode::CREATED } else { StatusCode::OK }, &material)
}

/// Removes a material (a seeded one too: it does not come back); with `If-Match` only the version
/// the client has seen (else 412). Jobs already submitted keep the values they were resolved with.
#[utoipa::path(delete, path = "/api/v1/materials/{name}", tag = "materials",
    params(
        ("name" = String, Path, description = "Material name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$"),
        DeleteHeaders),
    responses(
        (status = 204, description = "Deleted"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` does not hold (`E_PRECONDITION_FAILED`); the `ETag` header carries the current tag when the material exists", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name", body = Problem, content_type = "application/problem+json")))]
async fn delete_material(
    State(state): State<AppState>,
    AppPath(name): AppPath<MaterialName>,
    preconditions: Preconditions,
) -> AppResult<StatusCode> {
    let name = checked_name(name)?;
    let item = format!("material {name:?}");
    let guard = |current: Option<&Material>| preconditions.check(&item, current.map(etag_of).transpose()?.as_deref());
    if store::materials::delete(&state.db, &name, guard).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(unknown(&name))
    }
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(list_materials)).routes(routes!(get_material, put_material, delete_material))
}
