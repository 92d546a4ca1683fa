//! Snapshot of the whole OpenAPI document, so every API change shows up in review
//! (`cargo insta review`, or `INSTA_UPDATE=always cargo test -p kerf-server` to accept).

#[test]
fn openapi_document_snapshot() {
    let (_, document) = kerf_server::app::api();
    insta::assert_json_snapshot!("openapi", document);
}

/// utoipa names a schema after its type, so two types of one name in different modules would
/// silently share one entry. Every type that derives `ToSchema` must have its own name (its
/// `schema(as = ...)` name where it has one).
#[test]
fn schema_names_are_unique() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut names: std::collections::BTreeMap<String, Vec<String>> = std::collections::BTreeMap::new();
    let mut folders = vec![root.join("solver/src"), root.join("server/src")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            for (index, line) in lines.iter().enumerate() {
                if !line.contains("ToSchema") || !line.trim_start().starts_with("#[") {
                    continue;
                }
                let mut alias = None;
                for following in &lines[index + 1..] {
                    let following = following.trim_start();
                    if let Some(rest) = following.split("schema(as = ").nth(1) {
                        alias = rest.split(')').next().map(str::to_owned);
                    }
                    let declared = following
                        .strip_prefix("pub struct ")
                        .or_else(|| following.strip_prefix("pub enum "))
                        .or_else(|| following.strip_prefix("struct "))
                        .or_else(|| following.strip_prefix("enum "));
                    if let Some(declared) = declared {
                        let name: String = declared.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                        let place = format!("{}:{}", path.display(), index + 1);
                        names.entry(alias.clone().unwrap_or(name)).or_default().push(place);
                        break;
                    }
                }
            }
        }
    }
    assert!(names.len() > 50, "found only {} schema types", names.len());
    let shared: Vec<_> = names.iter().filter(|(_, places)| places.len() > 1).collect();
    assert!(shared.is_empty(), "schema names used by more than one type: {shared:#?}");
}

/// OpenAPI requires a description on every response.
#[test]
fn every_response_has_a_description() {
    let (_, document) = kerf_server::app::api();
    let json = serde_json::to_value(&document).unwrap();
    for (path, item) in json["paths"].as_object().unwrap() {
        for (method, operation) in item.as_object().unwrap() {
            for (status, response) in operation["responses"].as_object().unwrap() {
                let description = response["description"].as_str().unwrap_or_default();
                assert!(!description.is_empty(), "{method} {path} {status} has no description");
            }
        }
    }
}

/// Every tag an operation carries is listed with a description, so documentation generators
/// group and explain every operation.
#[test]
fn every_tag_is_described() {
    let (_, document) = kerf_server::app::api();
    let json = serde_json::to_value(&document).unwrap();
    let described: Vec<&str> = json["tags"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|tag| tag["description"].as_str().is_some_and(|text| !text.is_empty()))
        .map(|tag| tag["name"].as_str().unwrap())
        .collect();
    for (path, item) in json["paths"].as_object().unwrap() {
        for (method, operation) in item.as_object().unwrap() {
            for tag in operation["tags"].as_array().into_iter().flatten() {
                let tag = tag.as_str().unwrap();
                assert!(described.contains(&tag), "{method} {path}: tag {tag} has no description");
            }
        }
    }
}

/// Every `$ref` names a schema the document defines.
#[test]
fn every_reference_is_defined() {
    let (_, document) = kerf_server::app::api();
    let json = serde_json::to_value(&document).unwrap();
    let defined = json["components"]["schemas"].as_object().unwrap();
    let text = json.to_string();
    for piece in text.split("\"#/components/schemas/").skip(1) {
        let name = &piece[..piece.find('"').unwrap()];
        assert!(defined.contains_key(name), "#/components/schemas/{name} is referenced but not defined");
    }
}

/// Every solver endpoint answers JSON only and its `/program` sibling G-code only, so a generated
/// client has one answer type per operation; every API operation documents its 401 (the token)
/// with the bearer scheme.
#[test]
fn answers_and_the_token_are_documented() {
    let (_, document) = kerf_server::app::api();
    let json = serde_json::to_value(&document).unwrap();
    assert_eq!(json["components"]["securitySchemes"]["bearer"]["scheme"], "bearer");
    for path in ["/api/v1/deburr", "/api/v1/segment", "/api/v1/contour", "/api/v1/engagement", "/api/v1/predict"] {
        let content = json["paths"][path]["post"]["responses"]["200"]["content"].as_object().unwrap();
        assert_eq!(content.keys().collect::<Vec<_>>(), ["application/json"], "{path}");
        let program = format!("{path}/program");
        let content = json["paths"][&program]["post"]["responses"]["200"]["content"].as_object().unwrap();
        assert_eq!(content.keys().collect::<Vec<_>>(), ["text/x-gcode"], "{program}");
        for path in [path, &program] {
            assert!(json["paths"][path]["post"]["responses"]["429"].is_object(), "{path} has no 429");
        }
    }
    for (path, item) in json["paths"].as_object().unwrap() {
        if !path.starts_with("/api/v1/") {
            continue;
        }
        for (method, operation) in item.as_object().unwrap() {
            assert!(operation["responses"]["401"].is_object(), "{method} {path} has no 401");
        }
    }
}

/// What client generators need to read the document as meant: every union of objects tagged by
/// a property has a `discriminator` whose mapping names schemas with a `title`; no `allOf` takes
/// a `oneOf` (generators drop such a schema); every JSON answer an object (an `allOf` of
/// objects, with the check before), an array or a tagged union; binaries
/// are `format: binary`; `Problem.code` is open; every operation has an `operationId`.
#[test]
fn generators_read_the_document_as_meant() {
    let (_, document) = kerf_server::app::api();
    let json = serde_json::to_value(&document).unwrap();
    let schemas = json["components"]["schemas"].as_object().unwrap();
    let resolve = |schema: &serde_json::Value| -> serde_json::Value {
        match schema["$ref"].as_str() {
            Some(reference) => schemas[reference.trim_start_matches("#/components/schemas/")].clone(),
            None => schema.clone(),
        }
    };
    for union in ["Curve", "Stock", "Workpiece", "Stiffness", "PathInput", "SegmentInput", "Operation", "JobResult"] {
        let schema = &schemas[union];
        let property = schema["discriminator"]["propertyName"].as_str().unwrap_or_else(|| panic!("{union}: {schema}"));
        let mapping = schema["discriminator"]["mapping"].as_object().unwrap();
        assert_eq!(mapping.len(), schema["oneOf"].as_array().unwrap().len(), "{union}");
        for (tag, reference) in mapping {
            let member = resolve(&serde_json::json!({ "$ref": reference }));
            assert!(member["title"].is_string(), "{union} {tag} has no title");
            let text = member.to_string();
            assert!(text.contains(&format!("\"{property}\"")), "{union} {tag} lacks {property}");
        }
    }
    for (name, schema) in schemas {
        for part in schema["allOf"].as_array().into_iter().flatten() {
            assert!(resolve(part)["oneOf"].is_null(), "{name} is an allOf over a oneOf");
        }
    }
    // Points inside the requests' point lists have their number of coordinates.
    for (schema, list, fewest, most) in [
        ("ContourRequest", "/properties/contour", 2, 2),
        ("StockPolygon", "/properties/holes/items", 2, 2),
        ("EngagementPath", "/oneOf/0", 2, 2),
        ("PathInputPoints", "/properties/points", 3, 3),
        ("CurvePolyline", "/properties/points", 2, 3),
    ] {
        let point = &schemas[schema].pointer(list).unwrap_or_else(|| panic!("{schema}{list}"))["items"];
        assert_eq!(
            (point["minItems"].as_u64(), point["maxItems"].as_u64()),
            (Some(fewest), Some(most)),
            "{schema}{list}: {point}"
        );
    }
    for (tag, reference) in schemas["JobResult"]["discriminator"]["mapping"].as_object().unwrap() {
        let member = resolve(&serde_json::json!({ "$ref": reference }));
        assert!(member["properties"]["result"]["$ref"].is_string(), "JobResult {tag}: {member}");
    }
    assert!(schemas["Problem"]["properties"]["code"]["anyOf"][1]["type"] == "string", "Problem.code is open");
    assert_eq!(schemas["JobForm"]["properties"]["file"]["format"], "binary");
    let zip = &json["paths"]["/api/v1/jobs/{id}/outputs.zip"]["get"]["responses"]["200"]["content"]["application/zip"];
    assert_eq!(resolve(&zip["schema"])["format"], "binary", "{zip}");
    assert_eq!(schemas["Tool"]["properties"]["number"]["maximum"], 9999);
    assert_eq!(schemas["Tool"]["properties"]["flutes"]["maximum"], 32);
    let number = schemas["ToolRef"]["oneOf"].as_array().unwrap().iter().find(|member| member["type"] == "integer");
    assert_eq!(number.map(|number| (&number["minimum"], &number["maximum"])), Some((&1.into(), &9999.into())));
    assert_eq!(schemas["CurveCircle"]["properties"]["centre"]["minItems"], 2);
    assert_eq!(schemas["CurveCircle"]["properties"]["centre"]["maxItems"], 3);
    assert_eq!(schemas["StockBox"]["properties"]["min"]["maxItems"], 3);
    assert!(json["servers"].as_array().is_some_and(|servers| !servers.is_empty()));
    let mut operation_ids = std::collections::BTreeSet::new();
    for (path, item) in json["paths"].as_object().unwrap() {
        for (method, operation) in item.as_object().unwrap() {
            let id = operation["operationId"].as_str().unwrap_or_else(|| panic!("{method} {path}: no operationId"));
            assert!(operation_ids.insert(id.to_owned()), "operationId {id} twice");
            for (status, response) in operation["responses"].as_object().unwrap() {
                let success = status.starts_with('2');
                for (media, content) in response["content"].as_object().into_iter().flatten() {
                    let schema = resolve(&content["schema"]);
                    if success && media == "application/json" {
                        assert!(
                            schema["type"] == "object"
                                || schema["type"] == "array"
                                || schema["allOf"].is_array()
                                || schema["discriminator"].is_object(),
                            "{method} {path} {status}: the answer is not an object: {schema}"
                        );
                    }
                }
            }
        }
    }
}
