//! The web page (`web/`), compiled into the binary so a shop-floor PC needs only the executable.
//! Only the files listed here are served: nothing outside `web/` can be reached.

use axum::Router;
use axum::http::{HeaderValue, header};
use axum::response::IntoResponse;
use axum::routing::get;

/// One served file.
struct Asset {
    path: &'static str,
    media_type: &'static str,
    body: &'static [u8],
}

const ASSETS: &[Asset] = &[
    Asset { path: "/", media_type: "text/html; charset=utf-8", body: include_bytes!("../../web/index.html") },
    Asset { path: "/style.css", media_type: "text/css; charset=utf-8", body: include_bytes!("../../web/style.css") },
    Asset { path: "/app.js", media_type: "text/javascript; charset=utf-8", body: include_bytes!("../../web/app.js") },
    Asset {
        path: "/plot3d.js",
        media_type: "text/javascript; charset=utf-8",
        body: include_bytes!("../../web/plot3d.js"),
    },
];

/// Routes for the page's files.
pub fn router<S: Clone + Send + Sync + 'static>() -> Router<S> {
    ASSETS.iter().fold(Router::new(), |router, asset| {
        router.route(
            asset.path,
            get(move || async move {
                (
                    [
                        (header::CONTENT_TYPE, HeaderValue::from_static(asset.media_type)),
                        (header::CACHE_CONTROL, HeaderValue::from_static("no-cache")),
                    ],
                    asset.body,
                )
                    .into_response()
            }),
        )
    })
}
