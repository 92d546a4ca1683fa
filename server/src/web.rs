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

const HTML: &str = "text/html; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";

/// A file of `web/` served at its own path.
macro_rules! asset {
    ($path:literal, $media_type:expr) => {
        Asset { path: $path, media_type: $media_type, body: include_bytes!(concat!("../../web", $path)) }
    };
}

const ASSETS: &[Asset] = &[
    Asset { path: "/", media_type: HTML, body: include_bytes!("../../web/index.html") },
    asset!("/style.css", CSS),
    asset!("/app.js", JS),
    asset!("/plot3d.js", JS),
    asset!("/plot2d.js", JS),
    asset!("/views/contour.js", JS),
    asset!("/views/deburr.js", JS),
    asset!("/views/engagement.js", JS),
    asset!("/views/jobs.js", JS),
    asset!("/views/machines.js", JS),
    asset!("/views/segment.js", JS),
    asset!("/views/predict.js", JS),
    asset!("/views/tools.js", JS),
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
