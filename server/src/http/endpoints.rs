//! The solver endpoints `POST /api/v1/{name}` (docs/spec/api.md), generated from the capability registry
//! (`capabilities::with_registry!`): two small `#[utoipa::path]` handlers per capability with a
//! JSON body, the JSON answer and `POST /api/v1/{name}/program` with the program, documented with the capability's own [`Endpoint`](kerf_solver::capability::Endpoint)
//! texts, so the OpenAPI document names each capability's concrete request and answer. A
//! capability with an upload (`upload` in the registry) keeps its handler in `http/<module>.rs`; one
//! whose request may read a DXF drawing (`drawing`) takes JSON or a form with the file (`http::dxf::Submitted`).

use utoipa_axum::router::OpenApiRouter;

use crate::capabilities::with_registry;
use crate::state::AppState;

/// One capability's endpoint: a handler module for a JSON body, nothing for an upload.
macro_rules! endpoint {
    ($variant:ident, $module:ident, $capability:ident, $request:ident, $answer:ident, json($query:ident)) => {
        #[allow(non_snake_case, reason = "named after the registry's variant")]
        mod $variant {
            use axum::extract::State;
            use axum::http::HeaderMap;
            use axum::response::Response;
            use kerf_solver::capability::Capability;
            use kerf_solver::$module::{$answer, $capability, $request};

            use super::super::output::Negotiate;
            #[allow(unused_imports, reason = "one of them is this endpoint's query")]
            use super::super::output::{CandidateQuery, OutputQuery};
            use crate::error::{AppResult, Problem};
            use crate::extract::{AppJson, AppQuery};
            use crate::state::AppState;

            /// The query of the program route (`POST /api/v1/{name}/program`).
            type ProgramParams = <$query as Negotiate>::Program;
            /// The query of the stock route (`POST /api/v1/{name}/stock`).
            type StockParams = super::super::own_stock::StockQuery;

            /// The JSON answer; `?format=gcode` or an `Accept` preferring `text/x-gcode` still
            /// answer the program here (undocumented: the program route is the documented way).
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = <$capability as Capability>::NAME,
                operation_id = <$capability as Capability>::NAME,
                tag = <$capability as Capability>::NAME,
                summary = <$capability as Capability>::ENDPOINT.summary,
                description = <$capability as Capability>::ENDPOINT.description,
                request_body = $request,
                responses(
                    (status = 200, description = "The answer", body = $answer, content_type = "application/json"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn post(
                State(state): State<AppState>,
                headers: HeaderMap,
                AppQuery(query): AppQuery<$query>,
                AppJson(request): AppJson<$request>,
            ) -> AppResult<Response> {
                super::super::solve::answer::<$capability>(&state, request, None, query.ask(&headers)).await
            }

            /// The program of the same request: the answer's path as G-code.
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = format!("{}/program", <$capability as Capability>::NAME),
                operation_id = format!("{}_program", <$capability as Capability>::NAME),
                tag = <$capability as Capability>::NAME,
                summary = "The same request's answer as a G-code program",
                description = <$capability as Capability>::ENDPOINT.description,
                params(ProgramParams),
                request_body = $request,
                responses(
                    (status = 200, description = "The program", body = String, content_type = "text/x-gcode"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn program(
                State(state): State<AppState>,
                AppQuery(query): AppQuery<ProgramParams>,
                AppJson(request): AppJson<$request>,
            ) -> AppResult<Response> {
                super::super::solve::answer::<$capability>(&state, request, None, <$query as Negotiate>::program(query)).await
            }

            /// The stock as the request's own verification cuts its program, as binary glTF.
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = format!("{}/stock", <$capability as Capability>::NAME),
                operation_id = format!("{}_stock", <$capability as Capability>::NAME),
                tag = <$capability as Capability>::NAME,
                summary = "The stock as the request's own verification cuts its program, as binary glTF",
                description = "The program the answer writes (default output options, Fanuc) cut on the capability's own model (the model of the answer's `verification`, docs/spec/verify.md §9), as binary glTF (`model/gltf-binary`) coloured by deviation from the model's part (a model without a part, engagement's: by what the program cut, `extras.colouring` `cut`), with that cut's `verification` in its `extras.verification`; `upto_line` cuts only the moves up to a line (playback). In the request's units, as its answer (positions, `_DEVIATION` and `extras.verification`; `extras.units` names them). A request without a model (verification off, a `bore_block`, segment and resegment) is refused naming `verification`.",
                params(StockParams),
                request_body = $request,
                responses(
                    (status = 200, description = "The cut stock", body = super::super::own_stock::GlbFile, content_type = "model/gltf-binary"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn stock(
                State(state): State<AppState>,
                AppQuery(query): AppQuery<StockParams>,
                AppJson(request): AppJson<$request>,
            ) -> AppResult<Response> {
                super::super::own_stock::answer::<$capability>(&state, request, None, query.upto_line).await
            }
        }
    };
    ($variant:ident, $module:ident, $capability:ident, $request:ident, $answer:ident, drawing($query:ident)) => {
        #[allow(non_snake_case, reason = "named after the registry's variant")]
        mod $variant {
            use axum::extract::State;
            use axum::http::HeaderMap;
            use axum::response::Response;
            use kerf_solver::capability::Capability;
            use kerf_solver::$module::{$answer, $capability, $request};

            use super::super::output::Negotiate;
            #[allow(unused_imports, reason = "one of them is this endpoint's query")]
            use super::super::output::{CandidateQuery, OutputQuery};
            use crate::error::{AppResult, Problem};
            use crate::extract::AppQuery;
            use crate::http::dxf::{DrawingForm, Submitted};
            use crate::state::AppState;

            /// The query of the program route (`POST /api/v1/{name}/program`).
            type ProgramParams = <$query as Negotiate>::Program;
            /// The query of the stock route (`POST /api/v1/{name}/stock`).
            type StockParams = super::super::own_stock::StockQuery;

            /// The JSON answer (the request as JSON, or as a form with the DXF file of its `drawing`); `?format=gcode` or an `Accept` preferring `text/x-gcode` still
            /// answer the program here (undocumented: the program route is the documented way).
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = <$capability as Capability>::NAME,
                operation_id = <$capability as Capability>::NAME,
                tag = <$capability as Capability>::NAME,
                summary = <$capability as Capability>::ENDPOINT.summary,
                description = <$capability as Capability>::ENDPOINT.description,
                request_body(description = "The request as JSON, or a form with it in part `request` and the DXF file its `drawing` reads in part `drawing`.",
                    content(($request = "application/json"), (DrawingForm = "multipart/form-data"))),
                responses(
                    (status = 200, description = "The answer", body = $answer, content_type = "application/json"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn post(
                State(state): State<AppState>,
                headers: HeaderMap,
                AppQuery(query): AppQuery<$query>,
                Submitted(request, drawing): Submitted<$request>,
            ) -> AppResult<Response> {
                super::super::solve::answer::<$capability>(&state, request, drawing, query.ask(&headers)).await
            }

            /// The program of the same request: the answer's path as G-code.
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = format!("{}/program", <$capability as Capability>::NAME),
                operation_id = format!("{}_program", <$capability as Capability>::NAME),
                tag = <$capability as Capability>::NAME,
                summary = "The same request's answer as a G-code program",
                description = <$capability as Capability>::ENDPOINT.description,
                params(ProgramParams),
                request_body(description = "The request as JSON, or a form with it in part `request` and the DXF file its `drawing` reads in part `drawing`.",
                    content(($request = "application/json"), (DrawingForm = "multipart/form-data"))),
                responses(
                    (status = 200, description = "The program", body = String, content_type = "text/x-gcode"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn program(
                State(state): State<AppState>,
                AppQuery(query): AppQuery<ProgramParams>,
                Submitted(request, drawing): Submitted<$request>,
            ) -> AppResult<Response> {
                super::super::solve::answer::<$capability>(&state, request, drawing, <$query as Negotiate>::program(query)).await
            }

            /// The stock as the request's own verification cuts its program, as binary glTF.
            #[utoipa::path(post,
                context_path = "/api/v1/",
                path = format!("{}/stock", <$capability as Capability>::NAME),
                operation_id = format!("{}_stock", <$capability as Capability>::NAME),
                tag = <$capability as Capability>::NAME,
                summary = "The stock as the request's own verification cuts its program, as binary glTF",
                description = "The program the answer writes (default output options, Fanuc) cut on the capability's own model (the model of the answer's `verification`, docs/spec/verify.md §9), as binary glTF (`model/gltf-binary`) coloured by deviation from the model's part (a model without a part, engagement's: by what the program cut, `extras.colouring` `cut`), with that cut's `verification` in its `extras.verification`; `upto_line` cuts only the moves up to a line (playback). In the request's units, as its answer (positions, `_DEVIATION` and `extras.verification`; `extras.units` names them). A request without a model (verification off, a `bore_block`, segment and resegment) is refused naming `verification`.",
                params(StockParams),
                request_body(description = "The request as JSON, or a form with it in part `request` and the DXF file its `drawing` reads in part `drawing`.",
                    content(($request = "application/json"), (DrawingForm = "multipart/form-data"))),
                responses(
                    (status = 200, description = "The cut stock", body = super::super::own_stock::GlbFile, content_type = "model/gltf-binary"),
                    (status = 400, body = Problem, content_type = "application/problem+json"),
                    (status = 404, description = <$capability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
                    (status = 413, body = Problem, content_type = "application/problem+json"),
                    (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
                    (status = 415, body = Problem, content_type = "application/problem+json"),
                    (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
                    (status = 422, description = <$capability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
            pub async fn stock(
                State(state): State<AppState>,
                AppQuery(query): AppQuery<StockParams>,
                Submitted(request, drawing): Submitted<$request>,
            ) -> AppResult<Response> {
                super::super::own_stock::answer::<$capability>(&state, request, drawing, query.upto_line).await
            }
        }
    };
    ($variant:ident, $module:ident, $capability:ident, $request:ident, $answer:ident, upload) => {};
}

/// The routes of one capability's endpoint.
macro_rules! route {
    ($variant:ident, $module:ident, json) => {
        OpenApiRouter::new()
            .routes(utoipa_axum::routes!($variant::post))
            .routes(utoipa_axum::routes!($variant::program))
            .routes(utoipa_axum::routes!($variant::stock))
    };
    ($variant:ident, $module:ident, drawing) => {
        OpenApiRouter::new()
            .routes(utoipa_axum::routes!($variant::post))
            .routes(utoipa_axum::routes!($variant::program))
            .routes(utoipa_axum::routes!($variant::stock))
            // A form's DXF file has the upload limit; a JSON body keeps its own (`Submitted`).
            .layer(axum::extract::DefaultBodyLimit::disable())
    };
    ($variant:ident, $module:ident, upload) => {
        super::$module::router()
    };
}

/// Every capability's endpoint module and [`router`].
macro_rules! endpoints {
    ($($variant:ident => $module:ident::{$capability:ident, $request:ident, $answer:ident}, $body:ident $(($query:ident))?, $doc:literal;)+) => {
        $(endpoint!($variant, $module, $capability, $request, $answer, $body $(($query))?);)+

        /// The routes of every capability's endpoint, in registry order.
        pub fn router() -> OpenApiRouter<AppState> {
            OpenApiRouter::new()$(.merge(route!($variant, $module, $body)))+
        }
    };
}

with_registry!(endpoints);
