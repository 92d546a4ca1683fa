//! Numbers as programs print them, appended to the program's one buffer (bytes, all ASCII): a value with a fixed
//! number of decimals is rounded to a scaled integer and its digits written with the decimal point
//! inserted, the same text as `format!("{value:.4}")` (the standard library's exact decimal
//! rounding, ties to even) without its general path. Where the scaled product may be off by its
//! own rounding (within a few units in the last place of a tie, or beyond 2^53) and for values
//! that are not finite, the standard library's formatting is used, so the text is always that of
//! `format!`.

use std::io::Write as _;

/// Powers of ten for up to [`MAX_DECIMALS`] decimals.
const SCALES: [f64; 7] = [1.0, 10.0, 100.0, 1_000.0, 10_000.0, 100_000.0, 1_000_000.0];

/// The most decimals a post prints (a decimal format of 4 for mm, 5 or 6 for inch and degrees).
pub const MAX_DECIMALS: usize = SCALES.len() - 1;

/// The least value above zero a post printing `decimals` decimals writes: one unit in its last
/// place.
pub fn least_increment(decimals: usize) -> f64 {
    1.0 / SCALES[decimals.min(MAX_DECIMALS)]
}

/// Largest scaled magnitude written from an integer: far below 2^53, so the product's own
/// rounding error (half a unit in its last place) is below 2^-10 of a unit.
const SCALED_LIMIT: f64 = 1e15;

/// Relative width around a tie (a fraction of exactly one half) inside which the scaled product
/// is not trusted: eight times the product's largest rounding error.
const TIE_WINDOW: f64 = 8.0 * f64::EPSILON;

/// Room for a sign, 15 integer digits, the point and [`MAX_DECIMALS`] decimals.
const NUMBER_ROOM: usize = 32;

/// The value times 10^`decimals` rounded to an integer, when that is certainly the rounding of
/// the exact value (not within rounding error of a tie, finite and small enough).
fn scaled(value: f64, decimals: usize) -> Option<u64> {
    let product = value.abs() * SCALES[decimals];
    // NaN and infinities fail this too.
    if product.partial_cmp(&SCALED_LIMIT) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    // Below 2^53 and not negative: the conversion truncates exactly, and is the floor.
    let floor = product as u64;
    let fraction = product - floor as f64;
    if (fraction - 0.5).abs() <= product * TIE_WINDOW + f64::MIN_POSITIVE {
        return None;
    }
    Some(floor + u64::from(fraction > 0.5))
}

/// Powers of ten up to 10^16, to count digits.
const POWERS: [u64; 17] = {
    let mut powers = [1u64; 17];
    let mut k = 1;
    while k < 17 {
        powers[k] = powers[k - 1] * 10;
        k += 1;
    }
    powers
};

/// Appends `units` (a value times 10^`decimals`) with the decimal point inserted and `sign`
/// (if any) before it: written straight into room made at the buffer's end, then cut to its
/// length.
fn push_scaled(out: &mut Vec<u8>, sign: Option<u8>, units: u64, decimals: usize) {
    let (mut whole, mut fraction) = (units / POWERS[decimals], units % POWERS[decimals]);
    let mut digits = 1;
    while digits < 16 && whole >= POWERS[digits] {
        digits += 1;
    }
    let start = out.len();
    out.resize(start + NUMBER_ROOM, 0);
    let buffer = &mut out[start..];
    let mut length = 0;
    if let Some(sign) = sign {
        buffer[0] = sign;
        length = 1;
    }
    for at in (length..length + digits).rev() {
        buffer[at] = b'0' + (whole % 10) as u8;
        whole /= 10;
    }
    length += digits;
    if decimals > 0 {
        buffer[length] = b'.';
        for at in (length + 1..=length + decimals).rev() {
            buffer[at] = b'0' + (fraction % 10) as u8;
            fraction /= 10;
        }
        length += 1 + decimals;
    }
    out.truncate(start + length);
}

/// Appends `value` with `decimals` decimals (at most [`MAX_DECIMALS`]) as `format!` prints it,
/// except that a value rounding to zero is printed without a sign (never `-0.0000`), and with
/// `plus` a value that is not negative gets a `+` (Heidenhain's `X+10.0000`).
pub fn push_fixed(out: &mut Vec<u8>, value: f64, decimals: usize, plus: bool) {
    let decimals = decimals.min(MAX_DECIMALS);
    match scaled(value, decimals) {
        Some(units) => {
            let sign = if units != 0 && value < 0.0 {
                Some(b'-')
            } else if plus {
                Some(b'+')
            } else {
                None
            };
            push_scaled(out, sign, units, decimals);
        }
        None => {
            let text = format!("{value:.decimals$}");
            let negative_zero = text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.');
            let text = if negative_zero { &text[1..] } else { &text[..] };
            if plus && !text.starts_with('-') {
                out.push(b'+');
            }
            out.extend_from_slice(text.as_bytes());
        }
    }
}

/// Appends a feed: whole mm/min where exact, else one decimal (as `format!` prints them: `{:.0}`
/// and `{:.1}`).
pub fn push_feed(out: &mut Vec<u8>, feed: f64) {
    if feed > 0.0 && feed < SCALED_LIMIT {
        if feed.fract() == 0.0 {
            // A whole number below 2^53: exact as an integer.
            push_scaled(out, None, feed as u64, 0);
            return;
        }
        if let Some(units) = scaled(feed, 1) {
            push_scaled(out, None, units, 1);
            return;
        }
    }
    if feed.fract() == 0.0 {
        let _ = write!(out, "{feed:.0}");
    } else {
        let _ = write!(out, "{feed:.1}");
    }
}

/// Appends a whole number (a rounded spindle speed, a line number) as `Display` prints it.
pub fn push_whole(out: &mut Vec<u8>, value: f64) {
    if value > 0.0 && value < SCALED_LIMIT && value.fract() == 0.0 {
        push_scaled(out, None, value as u64, 0);
    } else {
        let _ = write!(out, "{value}");
    }
}

/// `value` with `decimals` decimals as [`push_fixed`] writes it.
pub fn fixed(value: f64, decimals: usize, plus: bool) -> String {
    let mut out = Vec::with_capacity(NUMBER_ROOM);
    push_fixed(&mut out, value, decimals, plus);
    text(out)
}

/// The text of a buffer the writers filled: ASCII, and UTF-8 in any case (only whole `str`s are
/// copied into it besides the digits).
pub fn text(bytes: Vec<u8>) -> String {
    String::from_utf8(bytes).unwrap_or_else(|error| String::from_utf8_lossy(error.as_bytes()).into_owned())
}

/// Whether `a` and `b` print as the same text with `decimals` decimals.
pub fn prints_equal(a: f64, b: f64, decimals: usize) -> bool {
    let decimals = decimals.min(MAX_DECIMALS);
    match (scaled(a, decimals), scaled(b, decimals)) {
        (Some(0), Some(0)) => true,
        (Some(x), Some(y)) => x == y && (a < 0.0) == (b < 0.0),
        _ => fixed(a, decimals, false) == fixed(b, decimals, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coordinate text as it was written with the standard library alone: the reference the
    /// fast path must equal.
    fn reference(value: f64) -> String {
        let text = format!("{value:.4}");
        if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') {
            text[1..].to_owned()
        } else {
            text
        }
    }

    fn reference_feed(feed: f64) -> String {
        if feed.fract() == 0.0 { format!("{feed:.0}") } else { format!("{feed:.1}") }
    }

    fn fixed4(value: f64) -> String {
        fixed(value, 4, false)
    }

    fn feed(value: f64) -> String {
        let mut out = Vec::new();
        push_feed(&mut out, value);
        text(out)
    }

    /// A small deterministic generator (xorshift64*), so a failure names a reproducible value.
    struct Draw(u64);

    impl Draw {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }

        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn special_values_read_as_the_standard_library_writes_them() {
        let values = [
            0.0,
            -0.0,
            -0.00001,
            -0.00005,
            0.00005,
            -0.00004999,
            0.03125,
            -0.03125,
            0.09375,
            1.00005,
            2.5e-5,
            7.5e-5,
            1.23455,
            -1.23455,
            12.0,
            -1.23456,
            999_999.999_95,
            1e-300,
            -1e-300,
            f64::MIN_POSITIVE,
            4.9e-324,
            1e11,
            1e11 + 0.00005,
            9.9e14,
            1e15,
            -1e16,
            1e300,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            (1u64 << 53) as f64 + 2.0,
            0.1 + 0.2,
        ];
        for value in values {
            assert_eq!(fixed4(value), reference(value), "{value:e}");
            assert_eq!(feed(value), reference_feed(value), "{value:e}");
            let mut whole = Vec::new();
            push_whole(&mut whole, value.round());
            assert_eq!(text(whole), format!("{}", value.round()), "{value:e}");
        }
    }

    #[test]
    fn random_values_and_ties_read_as_the_standard_library_writes_them() {
        let mut draw = Draw(0x9e37_79b9_7f4a_7c15);
        for _ in 0..100_000 {
            let bits = draw.next();
            // Any finite double, values of every magnitude, coordinates of a machine's size,
            // and exact and near ties of every decimal place.
            let values = [
                f64::from_bits(bits),
                (draw.unit() - 0.5) * 10f64.powi((draw.next() % 40) as i32 - 20),
                (draw.unit() - 0.5) * 4000.0,
                ((draw.next() % 2_000_000) as f64 - 1_000_000.0 + 0.5) / 10_000.0,
                ((draw.next() % 2_000_000) as f64 + 0.5) / 10.0,
                (draw.next() % (1 << 20)) as f64 / 32.0 - 16_384.0,
                f64::from_bits((((draw.next() % 2_000_000) as f64 + 0.5) / 10_000.0).to_bits() ^ (bits & 3)),
            ];
            for value in values {
                assert_eq!(fixed4(value), reference(value), "{value:e} ({:#x})", value.to_bits());
                assert_eq!(feed(value), reference_feed(value), "{value:e} ({:#x})", value.to_bits());
            }
        }
    }

    #[test]
    fn printed_equality_is_equality_of_the_text() {
        let mut draw = Draw(11);
        for _ in 0..100_000 {
            let a = (draw.unit() - 0.5) * 10f64.powi((draw.next() % 12) as i32 - 6);
            for b in [a + (draw.unit() - 0.5) * 2e-4, -a, a * (1.0 + 1e-12), 0.0, -0.0] {
                assert_eq!(prints_equal(a, b, 4), fixed4(a) == fixed4(b), "{a:e} {b:e}");
            }
        }
    }

    #[test]
    fn other_decimal_formats_and_signs() {
        let mut draw = Draw(7);
        for _ in 0..100_000 {
            let value = (draw.unit() - 0.5) * 10f64.powi((draw.next() % 16) as i32 - 6);
            for decimals in 0..=MAX_DECIMALS {
                let written = fixed(value, decimals, false);
                let text = format!("{value:.decimals$}");
                let zero = text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.');
                assert_eq!(written, if zero { &text[1..] } else { &text[..] }, "{value:e} {decimals}");
            }
        }
        let mut out = Vec::new();
        push_fixed(&mut out, 10.0, 4, true);
        push_fixed(&mut out, -0.00001, 4, true);
        push_fixed(&mut out, -2.5, 3, true);
        push_fixed(&mut out, 1e300, 1, true);
        let out = text(out);
        assert!(out.starts_with("+10.0000+0.0000-2.500+1000"), "{out}");
    }
}
