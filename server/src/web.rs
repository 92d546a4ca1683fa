//! The web page (`web/`), compiled into the binary so a shop-floor PC needs only the executable.
//! Every file of `web/` is served at its own path (listed at build time by `build.rs`), and
//! nothing outside `web/` can be reached, plus `/capabilities.js`, generated from the capability
//! registry. Each file has a
//! strong ETag (a hash of its bytes): the browser revalidates and gets 304 while the binary is the
//! same; answers are gzip-compressed when the browser accepts it.

use axum::Router;
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::IntoResponse;
use axum::routing::get;
use std::sync::LazyLock;
use tower_http::compression::CompressionLayer;

use crate::extract::strong_etag;

/// One served file.
#[derive(Clone, Copy)]
struct Asset {
    path: &'static str,
    media_type: &'static str,
    body: &'static [u8],
}

/// Every file of `web/` (`index.html` at `/`), listed by `build.rs`.
const ASSETS: &[Asset] = include!(concat!(env!("OUT_DIR"), "/web_assets.rs"));

/// `/capabilities.js`: the capability registry's names, in registry order, from which the page
/// builds its capability views (`web/views.js` loads `/views/{name}.js` for each).
static CAPABILITIES_MODULE: LazyLock<String> = LazyLock::new(|| {
    let names = serde_json::to_string(crate::capabilities::NAMES).unwrap_or_else(|_| "[]".to_owned());
    format!("// Generated from the server's capability registry.\nexport const CAPABILITIES = {names};\n")
});

/// The strong ETag of `body` ([`strong_etag`]) as a header value.
fn etag(body: &[u8]) -> HeaderValue {
    HeaderValue::from_str(&strong_etag(body)).unwrap_or_else(|_| HeaderValue::from_static("\"0\""))
}

/// Whether `If-None-Match` names `tag` (or `*`).
fn not_modified(headers: &HeaderMap, tag: &HeaderValue) -> bool {
    let Some(Ok(asked)) = headers.get(header::IF_NONE_MATCH).map(HeaderValue::to_str) else { return false };
    let tag = tag.to_str().unwrap_or_default();
    asked.split(',').map(|t| t.trim().trim_start_matches("W/")).any(|t| t == "*" || t == tag)
}

/// Routes for the page's files.
pub fn router<S: Clone + Send + Sync + 'static>() -> Router<S> {
    let generated = Asset {
        path: "/capabilities.js",
        media_type: "text/javascript; charset=utf-8",
        body: CAPABILITIES_MODULE.as_bytes(),
    };
    let routes = ASSETS.iter().copied().chain([generated]).fold(Router::new(), |router, asset| {
        let tag = etag(asset.body);
        router.route(
            asset.path,
            get(move |headers: HeaderMap| async move {
                let common =
                    [(header::ETAG, tag.clone()), (header::CACHE_CONTROL, HeaderValue::from_static("no-cache"))];
                if not_modified(&headers, &tag) {
                    return (StatusCode::NOT_MODIFIED, common).into_response();
                }
                (common, [(header::CONTENT_TYPE, HeaderValue::from_static(asset.media_type))], asset.body)
                    .into_response()
            }),
        )
    });
    routes.layer(CompressionLayer::new())
}
