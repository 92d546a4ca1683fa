//! HTTP routes, one module per resource, each with a `router()`; the solver endpoints are generated
//! from the capability registry in `endpoints`; `stream` holds the response bodies they hand out
//! a piece at a time.

pub mod contour;
pub mod dxf;
pub mod endpoints;
pub mod health;
pub mod job_stock;
pub mod jobs;
pub mod machines;
pub mod materials;
pub mod output;
pub mod own_stock;
pub mod predict;
pub mod solve;
pub mod stream;
pub mod tools;
mod upload;
pub mod verify;

use kerf_solver::ErrorCode;

use crate::error::{AppError, AppResult};

/// Most items one page of a registry list (tools, machines, materials) may ask for.
pub const PAGE_LIMIT_MAX: i64 = 1000;

/// The number of items a registry list answers: `limit` (1 to [`PAGE_LIMIT_MAX`], else 400
/// `E_QUERY` naming `limit`), every item when absent.
///
/// # Errors
/// 400 when `limit` is out of its range.
pub fn page_limit(limit: Option<i64>) -> AppResult<i64> {
    match limit {
        None => Ok(i64::MAX),
        Some(limit) if (1..=PAGE_LIMIT_MAX).contains(&limit) => Ok(limit),
        Some(limit) => Err(AppError::bad_request(
            ErrorCode::Query,
            "limit",
            format!("limit must be 1 to {PAGE_LIMIT_MAX} (got {limit})"),
        )),
    }
}

/// Paging of a list keyed by name (machines, materials): keyset, as the job list pages.
#[derive(Debug, Default, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct NamePage {
    /// Items per page, 1–1000; without it, every item. A page shorter than `limit` is the last.
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<i64>,
    /// Only the items whose name sorts after this one: the last name of the previous page.
    pub after: Option<String>,
}
