//! Response bodies handed to the connection a piece at a time, each holding its share of the
//! memory budget ([`crate::state::AppState::reserve_memory`]) until the client has read it.

use crate::store::packed::PIECE;

/// `bytes` in pieces of at most [`PIECE`] bytes.
pub fn pieces_of(mut bytes: axum::body::Bytes) -> impl Iterator<Item = std::io::Result<axum::body::Bytes>> + Send {
    std::iter::from_fn(move || (!bytes.is_empty()).then(|| Ok(bytes.split_to(bytes.len().min(PIECE)))))
}

/// A response body of `pieces`, taken one at a time as the client reads, that holds `permit` (a
/// share of the memory budget) until the last piece is out of its hands or the client went away.
pub fn held_body(
    permit: tokio::sync::OwnedSemaphorePermit,
    pieces: impl Iterator<Item = std::io::Result<axum::body::Bytes>> + Send + 'static,
) -> axum::body::Body {
    let mut pieces = pieces.peekable();
    let mut held = Some(permit);
    let pieces = std::iter::from_fn(move || {
        let piece = pieces.next();
        if pieces.peek().is_none() {
            // The last piece is out of our hands: its share goes back now.
            held.take();
        }
        piece
    });
    axum::body::Body::from_stream(futures_util::stream::iter(pieces))
}

/// A download of `length` bytes of `media_type` handed out in `pieces`, holding `permit` (its
/// share of the memory budget) until sent.
pub fn held_download(
    permit: tokio::sync::OwnedSemaphorePermit,
    pieces: impl Iterator<Item = std::io::Result<axum::body::Bytes>> + Send + 'static,
    length: usize,
    media_type: &'static str,
) -> axum::response::Response {
    let mut response = axum::response::IntoResponse::into_response(held_body(permit, pieces));
    response.headers_mut().insert(axum::http::header::CONTENT_TYPE, axum::http::HeaderValue::from_static(media_type));
    response.headers_mut().insert(axum::http::header::CONTENT_LENGTH, axum::http::HeaderValue::from(length));
    response
}
