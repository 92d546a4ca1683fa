//! The tool table over HTTP (docs/spec/api.md, Tools): `PUT/GET/DELETE /api/v1/tools/{number}`, list.

use axum::Json;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::Response;
use kerf_solver::tool::{TOOL_NUMBERS, Tool};
use kerf_solver::{ErrorCode, SolverError};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::page_limit;
use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppJson, AppPath, AppQuery, DeleteHeaders, Preconditions, ReplaceHeaders, etag_of, tagged};
use crate::state::AppState;
use crate::store;

/// The `{number}` path parameter.
#[derive(Debug, serde::Deserialize)]
struct ToolNumber {
    number: u32,
}

fn checked_number(ToolNumber { number }: ToolNumber) -> AppResult<u32> {
    if TOOL_NUMBERS.contains(&number) {
        Ok(number)
    } else {
        Err(SolverError::input("number", format!("tool number must be 1 to 9999 (got {number})")).into())
    }
}

/// Paging of the tool table: keyset, as the job list pages.
#[derive(Debug, Default, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
struct ToolPage {
    /// Tools per page, 1–1000; without it, every tool. A page shorter than `limit` is the last.
    #[param(minimum = 1, maximum = 1000)]
    limit: Option<i64>,
    /// Only the tools numbered above this one: the last number of the previous page.
    #[param(minimum = 0, maximum = 9999)]
    after: Option<u32>,
}

/// The registered tools, ordered by number, a page at a time with `limit` and `after`.
#[utoipa::path(get, path = "/api/v1/tools", tag = "tools", params(ToolPage),
    responses(
        (status = 200, body = Vec<Tool>),
        (status = 400, description = "`limit` or `after` is not a number in its range (`E_QUERY`, naming it)", body = Problem, content_type = "application/problem+json")))]
async fn list_tools(State(state): State<AppState>, AppQuery(page): AppQuery<ToolPage>) -> AppResult<Json<Vec<Tool>>> {
    let limit = page_limit(page.limit)?;
    let after = page.after.unwrap_or(0);
    if after > *TOOL_NUMBERS.end() {
        return Err(AppError::bad_request(
            ErrorCode::Query,
            "after",
            format!("after must be a tool number, 0 to {} (got {after})", TOOL_NUMBERS.end()),
        ));
    }
    Ok(Json(store::tools::list(&state.db, after, limit).await?))
}

/// One tool.
#[utoipa::path(get, path = "/api/v1/tools/{number}", tag = "tools",
    params(("number" = u32, Path, description = "Tool number, 1–9999", minimum = 1, maximum = 9999)),
    responses(
        (status = 200, body = Tool, headers(("ETag" = String, description = "The stored tool's strong entity tag: send it in `If-Match` to replace or delete only this version"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 422, body = Problem, content_type = "application/problem+json")))]
async fn get_tool(State(state): State<AppState>, AppPath(number): AppPath<ToolNumber>) -> AppResult<Response> {
    let number = checked_number(number)?;
    let tool = store::tools::get(&state.db, number)
        .await?
        .ok_or_else(|| AppError::not_found(format!("tool {number} is not in the tool table")))?;
    tagged(StatusCode::OK, &tool)
}

/// Registers or replaces a tool: 201 when new, 200 when replaced. `If-Match` replaces only the
/// version the client has seen, `If-None-Match: *` only creates; else 412 `E_PRECONDITION_FAILED`.
#[utoipa::path(put, path = "/api/v1/tools/{number}", tag = "tools",
    params(
        ("number" = u32, Path, description = "Tool number, 1–9999", minimum = 1, maximum = 9999),
        ReplaceHeaders),
    request_body = Tool,
    responses(
        (status = 201, description = "Created", body = Tool, headers(("ETag" = String, description = "The stored tool's strong entity tag"))),
        (status = 200, description = "Replaced", body = Tool, headers(("ETag" = String, description = "The stored tool's strong entity tag"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` or `If-None-Match` does not hold (`E_PRECONDITION_FAILED`, naming the header); the `ETag` header carries the current tag when the tool exists", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, body = Problem, content_type = "application/problem+json")))]
async fn put_tool(
    State(state): State<AppState>,
    AppPath(number): AppPath<ToolNumber>,
    preconditions: Preconditions,
    AppJson(mut tool): AppJson<Tool>,
) -> AppResult<Response> {
    let number = checked_number(number)?;
    if tool.number.is_some_and(|given| given != number) {
        return Err(SolverError::input("number", format!("body number differs from the path's {number}")).into());
    }
    tool.number = Some(number);
    tool.validate("")?;
    let item = format!("tool {number}");
    let created = store::tools::put(&state.db, &tool, |current| {
        preconditions.check(&item, current.map(etag_of).transpose()?.as_deref())
    })
    .await?;
    tagged(if created { StatusCode::CREATED } else { StatusCode::OK }, &tool)
}

/// Removes a tool; with `If-Match` only the version the client has seen (else 412).
#[utoipa::path(delete, path = "/api/v1/tools/{number}", tag = "tools",
    params(
        ("number" = u32, Path, description = "Tool number, 1–9999", minimum = 1, maximum = 9999),
        DeleteHeaders),
    responses(
        (status = 204, description = "Deleted"),
        (status = 400, description = "The number is not a number", body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 412, description = "`If-Match` does not hold (`E_PRECONDITION_FAILED`); the `ETag` header carries the current tag when the tool exists", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "The number is outside 1–9999", body = Problem, content_type = "application/problem+json")))]
async fn delete_tool(
    State(state): State<AppState>,
    AppPath(number): AppPath<ToolNumber>,
    preconditions: Preconditions,
) -> AppResult<StatusCode> {
    let number = checked_number(number)?;
    let item = format!("tool {number}");
    let guard = |current: Option<&Tool>| preconditions.check(&item, current.map(etag_of).transpose()?.as_deref());
    if store::tools::delete(&state.db, number, guard).await? {
        Ok(StatusCode::NO_CONTENT)
    } else {
        Err(AppError::not_found(format!("tool {number} is not in the tool table")))
    }
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(list_tools)).routes(routes!(get_tool, put_tool, delete_tool))
}
