//! The OpenAPI document (utoipa): its header here, the paths and schemas from the route modules.

use serde_json::{Map, Value, json};
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
    servers((url = "/", description = "The service that serves this document")),
    components(schemas(crate::http::contour::JsonOnly, crate::http::verify::VerifyFormat)),
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
        (name = "predict", description = "Machining-error prediction and path correction for ball-end-mill finishing (docs/spec/predict.md)"),
        (name = "resegment", description = "A G-code program's runs of feed moves cut again by the block-time rule (docs/spec/resegment.md)"),
        (name = "dxf", description = "Outlines and curves read from a DXF drawing (docs/spec/dxf.md)"),
        (name = "verify", description = "A G-code program cut out of the stock by its tool assembly, with what it gouges, leaves \
                                          or hits (docs/spec/verify.md)"),
        (name = "jobs", description = "Long or many computations as stored jobs, run by the service or by `kerf worker` processes \
                                        (docs/guide/jobs.md)")
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

/// Reshapes what utoipa derives from the Rust types into the forms client generators read as
/// meant (openapi-python-client, openapi-typescript, `@hey-api/openapi-ts`; `clients/generate`
/// runs them): every tagged union a `oneOf` of named, titled schemas with a `discriminator`; an
/// answer that flattens a union (`EngagementAnswer`) one object; each job result typed by its
/// operation; `Problem.code` an open string that lists the known codes; a tool number in a
/// request 1–9999 as the tool table's keys. The wire is unchanged: these are the same JSON
/// values, described in other words.
///
/// # Panics
/// If the document does not read back after reshaping, which the snapshot test shows first.
pub fn shape_for_generators(document: &mut utoipa::openapi::OpenApi) {
    let mut json = serde_json::to_value(&*document).expect("the OpenAPI document serialises");
    if let Some(schemas) = json.pointer_mut("/components/schemas").and_then(Value::as_object_mut) {
        tag_unions(schemas);
        flatten_unions_in_all_of(schemas);
        type_job_results(schemas, &answer_schemas());
        open_problem_code(schemas);
        limit_tool_numbers(schemas);
        limit_point_lengths(schemas);
    }
    *document = serde_json::from_value(json).expect("the reshaped OpenAPI document reads back");
}

/// The schema `schema` names through `$ref`s (at most 16 deep, so a circle of references ends).
fn resolve<'a>(schema: &'a Value, schemas: &'a Map<String, Value>) -> &'a Value {
    let mut schema = schema;
    for _ in 0..16 {
        let Some(name) =
            schema.get("$ref").and_then(Value::as_str).and_then(|r| r.strip_prefix("#/components/schemas/"))
        else {
            break;
        };
        match schemas.get(name) {
            Some(found) => schema = found,
            None => break,
        }
    }
    schema
}

/// The properties and required names of an object schema, with those of the objects it is an
/// `allOf` of (a flattened Rust struct).
fn object_fields(schema: &Value, schemas: &Map<String, Value>) -> (Map<String, Value>, Vec<String>) {
    let schema = resolve(schema, schemas);
    let mut properties = schema.get("properties").and_then(Value::as_object).cloned().unwrap_or_default();
    let mut required: Vec<String> = schema
        .get("required")
        .and_then(Value::as_array)
        .map(|names| names.iter().filter_map(Value::as_str).map(str::to_owned).collect())
        .unwrap_or_default();
    for part in schema.get("allOf").and_then(Value::as_array).into_iter().flatten() {
        let (more, needed) = object_fields(part, schemas);
        for (name, property) in more {
            properties.entry(name).or_insert(property);
        }
        required.extend(needed);
    }
    (properties, required)
}

/// The tags of a union member: each required property whose schema allows one string only.
fn member_tags(member: &Value, schemas: &Map<String, Value>) -> Vec<(String, String)> {
    let (properties, required) = object_fields(member, schemas);
    properties
        .iter()
        .filter(|(name, _)| required.contains(name))
        .filter_map(|(name, property)| {
            let values = property.get("enum").and_then(Value::as_array)?;
            match values.as_slice() {
                [Value::String(value)] => Some((name.clone(), value.clone())),
                _ => None,
            }
        })
        .collect()
}

/// `thick_tube` as `ThickTube`.
fn camel(value: &str) -> String {
    value
        .split(['_', '-', ' '])
        .map(|word| {
            let mut letters = word.chars();
            letters.next().map(|first| first.to_uppercase().chain(letters).collect::<String>()).unwrap_or_default()
        })
        .collect()
}

/// Gives every `oneOf` whose members all carry one tag property (serde's `tag = "kind"`) a
/// `discriminator` with its mapping, each inline member a schema of its own named after the
/// union and its tag (`CurveArc`, `OperationDeburr`) with that name as its `title`.
fn tag_unions(schemas: &mut Map<String, Value>) {
    let names: Vec<String> = schemas.keys().cloned().collect();
    for name in names {
        let Some(members) = schemas[&name].get("oneOf").and_then(Value::as_array).cloned() else {
            continue;
        };
        let tags: Vec<Vec<(String, String)>> = members.iter().map(|member| member_tags(member, schemas)).collect();
        let Some(property) = tags
            .first()
            .into_iter()
            .flatten()
            .map(|(property, _)| property.clone())
            .find(|property| tags.iter().all(|member| member.iter().any(|(candidate, _)| candidate == property)))
        else {
            continue;
        };
        let mut mapping = Map::new();
        let mut references = Vec::new();
        for (member, tags) in members.into_iter().zip(&tags) {
            let Some((_, value)) = tags.iter().find(|(candidate, _)| *candidate == property) else { continue };
            let reference = match member.get("$ref").and_then(Value::as_str) {
                Some(reference) => reference.to_owned(),
                None => {
                    let member_name = format!("{name}{}", camel(value));
                    let mut member = member;
                    if let Some(fields) = member.as_object_mut() {
                        fields.insert("title".to_owned(), Value::String(member_name.clone()));
                    }
                    assert!(
                        schemas.insert(member_name.clone(), member).is_none(),
                        "the union member {member_name} has the name of another schema"
                    );
                    format!("#/components/schemas/{member_name}")
                }
            };
            mapping.insert(value.clone(), Value::String(reference.clone()));
            references.push(json!({ "$ref": reference }));
        }
        if let Some(union) = schemas.get_mut(&name).and_then(Value::as_object_mut) {
            union.insert("oneOf".to_owned(), Value::Array(references));
            union.insert("discriminator".to_owned(), json!({ "propertyName": property, "mapping": mapping }));
        }
    }
}

/// Makes an `allOf` that flattens a union (a struct with a `#[serde(flatten)]` untagged enum, as
/// `EngagementAnswer`) one object: every member's properties, required where every member
/// requires them. Generators cannot take `allOf` over a `oneOf`.
fn flatten_unions_in_all_of(schemas: &mut Map<String, Value>) {
    let names: Vec<String> = schemas.keys().cloned().collect();
    for name in names {
        let Some(parts) = schemas[&name].get("allOf").and_then(Value::as_array).cloned() else {
            continue;
        };
        if !parts.iter().any(|part| resolve(part, schemas).get("oneOf").is_some()) {
            continue;
        }
        let mut properties = Map::new();
        let mut required: Vec<String> = Vec::new();
        for part in &parts {
            let resolved = resolve(part, schemas);
            match resolved.get("oneOf").and_then(Value::as_array) {
                Some(members) => {
                    let mut in_every: Option<Vec<String>> = None;
                    for member in members {
                        let (more, needed) = object_fields(member, schemas);
                        for (field, property) in more {
                            properties.entry(field).or_insert(property);
                        }
                        in_every = Some(match in_every {
                            None => needed,
                            Some(before) => before.into_iter().filter(|field| needed.contains(field)).collect(),
                        });
                    }
                    required.extend(in_every.unwrap_or_default());
                }
                None => {
                    let (more, needed) = object_fields(part, schemas);
                    for (field, property) in more {
                        properties.entry(field).or_insert(property);
                    }
                    required.extend(needed);
                }
            }
        }
        required.sort();
        required.dedup();
        let mut object = json!({ "type": "object", "required": required, "properties": properties });
        if let Some(description) = schemas[&name].get("description") {
            object["description"] = description.clone();
        }
        schemas.insert(name, object);
    }
}

/// Every capability's name and the name of its answer's schema, from the registry.
fn answer_schemas() -> Vec<(&'static str, String)> {
    macro_rules! answers {
        ($($variant:ident => $module:ident::{$capability:ident, $request:ident, $answer:ident}, $body:ident $(($query:ident))?, $doc:literal;)+) => {
            vec![$((
                <kerf_solver::$module::$capability as kerf_solver::capability::Capability>::NAME,
                <kerf_solver::$module::$answer as utoipa::ToSchema>::name().into_owned(),
            )),+]
        };
    }
    crate::capabilities::with_registry!(answers)
}

/// Types `JobResult.result` by the operation: one member per capability (`JobResultDeburr` with
/// the `DeburrAnswer`, ...), told apart by `operation`.
fn type_job_results(schemas: &mut Map<String, Value>, answers: &[(&'static str, String)]) {
    let Some(generic) = schemas.get("JobResult").cloned() else { return };
    let (properties, required) = object_fields(&generic, schemas);
    let mut mapping = Map::new();
    let mut references = Vec::new();
    for (operation, answer) in answers {
        let member_name = format!("JobResult{}", camel(operation));
        let mut member_properties = properties.clone();
        member_properties.insert(
            "operation".to_owned(),
            json!({ "type": "string", "enum": [operation], "description": "The operation's name." }),
        );
        member_properties.insert(
            "result".to_owned(),
            json!({ "$ref": format!("#/components/schemas/{answer}"),
                    "description": format!("Its answer, byte for byte as `POST /api/v1/{operation}` answers JSON.") }),
        );
        let member = json!({
            "type": "object",
            "title": member_name,
            "description": format!("The result of a `{operation}` operation."),
            "required": required,
            "properties": member_properties,
        });
        assert!(schemas.insert(member_name.clone(), member).is_none(), "{member_name} is taken");
        let reference = format!("#/components/schemas/{member_name}");
        mapping.insert((*operation).to_owned(), Value::String(reference.clone()));
        references.push(json!({ "$ref": reference }));
    }
    let mut union = json!({
        "oneOf": references,
        "discriminator": { "propertyName": "operation", "mapping": mapping },
    });
    if let Some(description) = generic.get("description") {
        union["description"] = description.clone();
    }
    schemas.insert("JobResult".to_owned(), union);
}

/// `Problem.code` as an open string: a known `ErrorCode` or any other string, so that a client
/// generated today reads a code added later.
fn open_problem_code(schemas: &mut Map<String, Value>) {
    let Some(code) = schemas.get_mut("Problem").and_then(|problem| problem.pointer_mut("/properties/code")) else {
        return;
    };
    let description = code.get("description").and_then(Value::as_str).unwrap_or_default().to_owned();
    *code = json!({
        "anyOf": [{ "$ref": "#/components/schemas/ErrorCode" }, { "type": "string" }],
        "description": format!("{description} One of `ErrorCode` today; later versions may add codes, so read it as an open string."),
    });
}

/// Gives the tool number of `ToolRef` (a request's `tool`, a number or an inline tool) the range
/// of the tool table's keys; utoipa takes no limits on an enum variant's field.
fn limit_tool_numbers(schemas: &mut Map<String, Value>) {
    let members = schemas.get_mut("ToolRef").and_then(|tool| tool.get_mut("oneOf")).and_then(Value::as_array_mut);
    for member in members.into_iter().flatten() {
        if member.get("type").and_then(Value::as_str) == Some("integer") {
            member["minimum"] = json!(kerf_solver::tool::TOOL_NUMBERS.start());
            member["maximum"] = json!(kerf_solver::tool::TOOL_NUMBERS.end());
        }
    }
}

/// The point lists of the requests, as (schema, JSON pointer to the list in it, fewest and most
/// coordinates of a point): the server reads these points as `[x, y]` or `[x, y, z]` arrays of
/// that length, which utoipa cannot say of a list's items.
const POINT_LISTS: [(&str, &str, u64, u64); 9] = [
    ("ContourRequest", "/properties/contour", 2, 2),
    ("LoopsRequest", "/properties/path", 2, 2),
    ("StockPolygon", "/properties/outer", 2, 2),
    ("StockPolygon", "/properties/holes/items", 2, 2),
    ("EngagementStock", "/properties/holes/items", 2, 2),
    ("EngagementPath", "/oneOf/0", 2, 2),
    ("PathInputPoints", "/properties/points", 3, 3),
    ("CurvePolyline", "/properties/points", 2, 3),
    ("CurveBspline", "/properties/control_points", 2, 3),
];

/// Gives the points of the requests' point lists their number of coordinates ([`POINT_LISTS`]);
/// a list the document no longer has is left out (the snapshot test shows it).
fn limit_point_lengths(schemas: &mut Map<String, Value>) {
    for (schema, list, fewest, most) in POINT_LISTS {
        let point =
            schemas.get_mut(schema).and_then(|schema| schema.pointer_mut(list)).and_then(|list| list.get_mut("items"));
        if let Some(point) = point.filter(|point| point.get("type").and_then(Value::as_str) == Some("array")) {
            point["minItems"] = json!(fewest);
            point["maxItems"] = json!(most);
        }
    }
}
