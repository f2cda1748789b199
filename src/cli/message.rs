//! The one line of an error: numbers written as people write them,
//! control characters shown rather than obeyed, the engine's setting
//! names replaced by the flags that set them, and a bound on the length.

/// Longest error message printed whole, characters: far beyond any
/// message of spherecal's own; only one that echoes a hostile input (a
/// line of a gigabyte) is longer.
pub const MAX_MESSAGE_CHARS: usize = 2000;

/// `message` cut in the middle to at most [`MAX_MESSAGE_CHARS`]: the
/// start (what is wrong) and the end (the file) are kept, the middle is
/// replaced by how many characters were left out.
#[must_use]
pub fn bounded_message(message: &str) -> String {
    let n = message.chars().count();
    if n <= MAX_MESSAGE_CHARS {
        return message.to_owned();
    }
    let keep = MAX_MESSAGE_CHARS / 2;
    let head: String = message.chars().take(keep).collect();
    let tail: String = message.chars().skip(n - keep).collect();
    format!("{head}… ({} characters left out) …{tail}", n - 2 * keep)
}

/// The one line printed after `error: `: numbers written out in full by
/// an engine message shown as people write them ([`readable_numbers`]),
/// control characters (a line feed in a file name) written as escapes so
/// the message stays one line, then cut to [`MAX_MESSAGE_CHARS`]
/// ([`bounded_message`]).
#[must_use]
pub fn error_line(message: &str) -> String {
    let one_line: String = message
        .chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect();
    bounded_message(&readable_numbers(&one_line))
}

/// Digits a number may have before it is rewritten in scientific
/// notation: more than any measurement in mm or deg has.
const LONG_NUMBER_DIGITS: usize = 18;

/// `message` with every number of more than [`LONG_NUMBER_DIGITS`]
/// digits (a `1e308` that a message printed in full, 309 digits, or a
/// `1e-300` with 300 zeros) shown as [`numeric::show`] writes it:
/// `1e308`. Other text, and numbers inside words (`p123…`), are kept.
///
/// [`numeric::show`]: crate::engine::base::numeric::show
#[must_use]
pub fn readable_numbers(message: &str) -> String {
    let bytes = message.as_bytes();
    let mut out = String::with_capacity(message.len());
    let mut last = 0;
    let mut i = 0;
    while i < bytes.len() {
        let starts_number = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'));
        if !starts_number {
            i += 1;
            continue;
        }
        let start = if i > 0 && bytes[i - 1] == b'-' {
            i - 1
        } else {
            i
        };
        let mut end = i;
        while end < bytes.len() && (bytes[end].is_ascii_digit() || bytes[end] == b'.') {
            end += 1;
        }
        let token = message[start..end].trim_end_matches('.');
        let digits = token.bytes().filter(u8::is_ascii_digit).count();
        let followed_by_word =
            end < bytes.len() && (bytes[end].is_ascii_alphabetic() || bytes[end] == b'_');
        match token.parse::<f64>() {
            Ok(v) if digits > LONG_NUMBER_DIGITS && !followed_by_word => {
                out.push_str(&message[last..start]);
                out.push_str(&crate::engine::base::numeric::show(v));
                last = start + token.len();
            }
            _ => {}
        }
        i = end.max(i + 1);
    }
    out.push_str(&message[last..]);
    out
}

/// `message` with the engine's names of settings replaced by the flags
/// that set them (`names`: engine name, flag), so that an option error
/// names what the user typed. A name is replaced where it stands as a
/// word of its own (`stripe_noise`, not `max_stripe_noise_x`).
#[must_use]
pub fn name_flags(message: &str, names: &[(&str, &str)]) -> String {
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'-';
    let mut text = message.to_owned();
    for (name, flag) in names {
        let mut out = String::with_capacity(text.len());
        let mut rest = text.as_str();
        while let Some(at) = rest.find(name) {
            let before = rest[..at].bytes().last();
            let after = rest[at + name.len()..].bytes().next();
            out.push_str(&rest[..at]);
            if before.is_some_and(word) || after.is_some_and(word) {
                out.push_str(name);
            } else {
                out.push_str(flag);
            }
            rest = &rest[at + name.len()..];
        }
        out.push_str(rest);
        text = out;
    }
    text
}
