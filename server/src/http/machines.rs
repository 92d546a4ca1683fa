//! The machines registry over HTTP (docs/spec/api.md, Machines): `PUT/GET/DELETE /api/v1/machines/{name}`,
//! list. A machine is a controller profile (block processing time, feed limit, dialect, margins);
//! a solver request that names it takes its values as defaults.

use axum::Json;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::Response;
use kerf_solver::SolverError;
use kerf_solver::gcode::Dialect;
use kerf_solver::machine::{MachineProfile, validate_machine_name};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::{NamePage, page_limit};
use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppJson, AppPath, AppQuery, DeleteHeaders, Preconditions, ReplaceHeaders, etag_of, tagged};
use crate::state::AppState;
use crate::store;

/// The `{name}` path parameter.
#[derive(Debug, serde::Deserialize)]
struct MachineName {
    name: String,
}

fn checked_name(MachineName { name }: MachineName) -> AppResult<String> {
    validate_machine_name(&name)?;
    Ok(name)
}

fn unknown(name: &str) -> AppError {
    AppError::not_found(format!("machine {name:?} is not registered"))
}

/// The registered machines, ordered by name, a page at a time with `limit` and `after`.
#[utoipa::path(get, path = "/api/v1/machines", tag = "machines", params(NamePage),
    responses(
        (status = 200, body = Vec<MachineProfile>),
        (status = 400, description = "`limit` is not a number from 1 to 1000 (`E_QUERY`, naming it)", body = Problem, content_type = "application/problem+json")))]
async fn list_machines(
    State(state): State<AppState>,
    AppQuery(page): AppQuery<NamePage>,
) -> AppResult<Json<Vec<MachineProfile>>> {
    let limit = page_limit(page.limit)?;
    Ok(Json(store::machines::list(&state.db, page.after.as_deref(), limit).await?))
}

/// One machine.
#[utoipa::path(get, path = "/api/v1/machines/{name}", tag = "machines",
    params(("name" = String, Path, description = "Machine name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$")),
    responses(
        (status = 200, body = MachineProfile, headers(("ETag" = String, description = "The stored machine's strong entity tag: send it in `If-Match` to replace or delete only this version"))),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name", body = Problem, content_type = "application/problem+json")))]
async fn get_machine(State(state): State<AppState>, AppPath(name): AppPath<MachineName>) -> AppResult<Response> {
    let name = checked_name(name)?;
    let machine = store::machines::get(&state.db, &name).await?.ok_or_else(|| unknown(&name))?;
    tagged(StatusCode::OK, &machine)
}

/// Registers or replaces a machine: 201 when new, 200 when replaced.
/// `If-Match` replaces only the version the client has seen, `If-None-Match: *` only creates;
/// else 412 `E_PRECONDITION_FAILED`.
#[utoipa::path(put, path = "/api/v1/machines/{name}", tag = "machines",
    params(
        ("name" = String, Path, description = "Machine name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$"),
        ReplaceHeaders),
    request_body = MachineProfile,
    responses(
        (status = 201, description = "Created", body = MachineProfile, headers(("ETag" = String, description = "The stored machine's strong entity tag"))),
        (status = 200, description = "Replaced", body = MachineProfile, headers(("ETag" = String, description = "The stored machine's strong entity tag"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` or `If-None-Match` does not hold (`E_PRECONDITION_FAILED`, naming the header); the `ETag` header carries the current tag when the machine exists", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name or value", body = Problem, content_type = "application/problem+json")))]
async fn put_machine(
    State(state): State<AppState>,
    AppPath(name): AppPath<MachineName>,
    preconditions: Preconditions,
    AppJson(mut machine): AppJson<MachineProfile>,
) -> AppResult<Response> {
    let name = checked_name(name)?;
    if machine.name.as_ref().is_some_and(|given| *given != name) {
        return Err(SolverError::input("name", format!("body name differs from the path's {name:?}")).into());
    }
    machine.name = Some(name);
    machine.validate()?;
    let item = format!("machine {:?}", machine.name.as_deref().unwrap_or_default());
    let created = store::machines::put(&state.db, &machine, |current| {
        preconditions.check(&item, current.map(etag_of).transpose()?.as_deref())
    })
    .await?;
    tagged(if created { StatusCode::CREATED } else { StatusCode::OK }, &machine)
}

/// Removes a machine; with `If-Match` only the version the client has seen (else 412). Jobs
/// already submitted keep the profile they were resolved with.
#[utoipa::path(delete, path = "/api/v1/machines/{name}", tag = "machines",
    params(
        ("name" = String, Path, description = "Machine name: 1–64 letters, digits, `-`, `_`, `.`, not starting with `.`", pattern = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,63}$"),
        DeleteHeaders),
    responses(
        (status = 204, description = "Deleted"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` does not hold (`E_PRECONDITION_FAILED`); the `ETag` header carries the current tag when the machine exists", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad name", body = Problem, content_type = "application/problem+json")))]
async fn delete_machine(
    State(state): State<AppState>,
    AppPath(name): AppPath<MachineName>,
    preconditions: Preconditions,
) -> AppResult<StatusCode> {
    let name = checked_name(name)?;
    let item = format!("machine {name:?}");
    let guard =
        |current: Option<&MachineProfile>| preconditions.check(&item, current.map(etag_of).transpose()?.as_deref());
    if store::machines::delete(&state.db, &name, guard).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(unknown(&name))
    }
}

/// The dialect of a program: the one the query asks for, else the machine's, else Fanuc.
pub fn dialect(asked: Option<Dialect>, machine: Option<&MachineProfile>) -> Dialect {
    asked.or(machine.map(|m| m.dialect)).unwrap_or_default()
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(list_machines)).routes(routes!(get_machine, put_machine, delete_machine))
}
