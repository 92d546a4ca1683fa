//! JSON text of the large answers (engagement samples, contour moves, segment points) written by
//! hand exactly as `serde_json` writes it: serde writes the rest of an answer with the large list
//! left empty, and the list is written into its place.

/// Writes a float as `serde_json` does: the shortest text that reads back the same, `null` when
/// not finite.
pub(crate) fn float(out: &mut Vec<u8>, value: f64) {
    if value.is_finite() {
        out.extend_from_slice(zmij::Buffer::new().format_finite(value).as_bytes());
    } else {
        out.extend_from_slice(b"null");
    }
}

/// Where `marker` (e.g. `"samples":[]`) starts in `text`, in order. No JSON string can hold a
/// marker's unescaped quotes, so each is a key serde wrote.
pub(crate) fn marks(text: &[u8], marker: &[u8]) -> Vec<usize> {
    text.windows(marker.len()).enumerate().filter(|(_, window)| *window == marker).map(|(at, _)| at).collect()
}
