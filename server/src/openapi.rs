//! The OpenAPI document (utoipa): its header here, the paths and schemas from the route modules.

use utoipa::OpenApi;

/// Document header; `app::router` adds every route's path and schemas.
#[derive(OpenApi)]
#[openapi(
    info(
        title = "kerf",
        description = "CAM web service: tool-centre paths as JSON or G-code. Lengths in mm, angles in degrees \
                       (`_deg`), feed in mm/min, times in s (`_s`) or ms (`_ms`). Every error is \
                       application/problem+json (RFC 9457) with a stable `code` and the fields at fault in `errors`.",
        license(name = "MIT OR Apache-2.0")
    ),
    components(schemas(crate::http::output::Format, crate::http::contour::JsonOnly)),
    tags(
        (name = "service", description = "Health"),
        (name = "tools", description = "The tool table, keyed by tool number"),
        (name = "deburr", description = "Cross-hole deburring with a ball end mill (docs/spec/deburr.md)"),
        (name = "machines", description = "Controller profiles (block processing time, feed limit, dialect), keyed by name (docs/spec/segment.md)"),
        (name = "materials", description = "Work materials with their Kienzle values (k_c1.1, m_c), keyed by name; \
                                             engagement requests name them for torque and power (docs/spec/engagement.md §11)"),
        (name = "segment", description = "Line-segment approximation with the chord error from the block processing time (docs/spec/segment.md)"),
        (name = "contour", description = "Layered contour milling with corner loops and inside-corner relief (docs/spec/contour.md)"),
        (name = "engagement", description = "Tool–workpiece engagement along a path, chip thickness per flute count and \
                                              the recommended flute counts (docs/spec/engagement.md)"),
        (name = "predict", description = "Machining-error prediction and path correction for ball-end-mill finishing (docs/spec/predict.md)")
    )
)]
pub struct ApiDoc;

/// Gives every response without a description its status's reason phrase (OpenAPI requires a
/// description on every response, and utoipa leaves out the empty ones), and documents the 400
/// of every operation with parameters.
pub fn describe_responses(document: &mut utoipa::openapi::OpenApi) {
    use utoipa::openapi::RefOr;
    for item in document.paths.paths.values_mut() {
        let operations =
            [&mut item.get, &mut item.put, &mut item.post, &mut item.delete, &mut item.patch, &mut item.head];
        for operation in operations.into_iter().flatten() {
            // The path and query extractors answer 400 for a parameter that does not parse.
            if operation.parameters.as_ref().is_some_and(|parameters| !parameters.is_empty()) {
                operation.responses.responses.entry("400".to_owned()).or_insert_with(|| {
                    RefOr::T(
                        utoipa::openapi::ResponseBuilder::new()
                            .description("A path or query parameter that does not parse")
                            .content(
                                "application/problem+json",
                                utoipa::openapi::Content::new(Some(RefOr::Ref(
                                    utoipa::openapi::Ref::from_schema_name("Problem"),
                                ))),
                            )
                            .build(),
                    )
                });
            }
            for (status, response) in &mut operation.responses.responses {
                if let RefOr::T(response) = response
                    && response.description.is_empty()
                {
                    let reason = status
                        .parse::<u16>()
                        .ok()
                        .and_then(|code| axum::http::StatusCode::from_u16(code).ok())
                        .and_then(|code| code.canonical_reason())
                        .unwrap_or("Response");
                    reason.clone_into(&mut response.description);
                }
            }
        }
    }
}

/// Documents the optional API token: a bearer scheme, every operation open without it or with it
/// (the server asks for it only when `--api-token` is set), and a 401 on every `/api/v1` operation
/// (with a token set, changes and solver calls need it; with `--private`, reads too).
pub fn describe_security(document: &mut utoipa::openapi::OpenApi) {
    use utoipa::openapi::security::{Http, HttpAuthScheme, SecurityRequirement, SecurityScheme};
    use utoipa::openapi::{Content, Ref, RefOr, ResponseBuilder};
    let components = document.components.get_or_insert_with(Default::default);
    components.add_security_scheme("bearer", SecurityScheme::Http(Http::new(HttpAuthScheme::Bearer)));
    document.security =
        Some(vec![SecurityRequirement::default(), SecurityRequirement::new("bearer", Vec::<String>::new())]);
    let unauthorised = ResponseBuilder::new()
        .description("Missing or wrong API token (only when the service has one)")
        .content("application/problem+json", Content::new(Some(RefOr::Ref(Ref::from_schema_name("Problem")))))
        .build();
    for (path, item) in &mut document.paths.paths {
        if !path.starts_with("/api/v1/") {
            continue;
        }
        let operations =
            [&mut item.get, &mut item.put, &mut item.post, &mut item.delete, &mut item.patch, &mut item.head];
        for operation in operations.into_iter().flatten() {
            operation.responses.responses.entry("401".to_owned()).or_insert_with(|| RefOr::T(unauthorised.clone()));
        }
    }
}

/// Documents the answers of a database in trouble: 503 `E_UNAVAILABLE` with `Retry-After` on every
/// `/api/v1` operation (each may read the store: a tool by number, a job), and 507
/// `E_STORAGE_FULL` on every operation that writes (PUT, DELETE, a job's submission).
pub fn describe_storage(document: &mut utoipa::openapi::OpenApi) {
    use utoipa::openapi::{Content, Ref, RefOr, ResponseBuilder};
    let problem = || Content::new(Some(RefOr::Ref(Ref::from_schema_name("Problem"))));
    let unavailable = ResponseBuilder::new()
        .description(
            "The database cannot be reached (`E_UNAVAILABLE`); nothing was stored; try again after `Retry-After`",
        )
        .header(
            "Retry-After",
            utoipa::openapi::Header::new(
                utoipa::openapi::ObjectBuilder::new().schema_type(utoipa::openapi::schema::Type::Integer),
            ),
        )
        .content("application/problem+json", problem())
        .build();
    let full = ResponseBuilder::new()
        .description("The database's disk is full (`E_STORAGE_FULL`); nothing was stored; reads still work")
        .content("application/problem+json", problem())
        .build();
    for (path, item) in &mut document.paths.paths {
        if !path.starts_with("/api/v1/") {
            continue;
        }
        let writes = path == "/api/v1/jobs";
        for (operation, stores) in [
            (&mut item.get, false),
            (&mut item.put, true),
            (&mut item.post, writes),
            (&mut item.delete, true),
            (&mut item.patch, true),
            (&mut item.head, false),
        ] {
            let Some(operation) = operation else { continue };
            operation.responses.responses.entry("503".to_owned()).or_insert_with(|| RefOr::T(unavailable.clone()));
            if stores {
                operation.responses.responses.entry("507".to_owned()).or_insert_with(|| RefOr::T(full.clone()));
            }
        }
    }
}
