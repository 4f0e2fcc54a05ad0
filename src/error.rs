//! The one error type of the library: each variant renders as a single line that names the
//! file or option at fault and the reason, as the CLI prints it. Messages echo file contents,
//! names and option values: [`one_line`] and [`escaped`] are the one way to print them, with
//! every character that a terminal would act on escaped.

use std::borrow::Cow;
use std::fmt::Write;
use std::path::PathBuf;

/// Everything that can go wrong in asperity.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its content is not what its format requires (truncated, corrupt,
    /// no topography in it, NaN heights, …).
    #[error("{}: {reason}", path.display())]
    File { path: PathBuf, reason: String },
    /// An option or parameter value that the physics or the grid cannot take.
    #[error("{option}: {reason}")]
    Invalid { option: String, reason: String },
    /// An iterative solver stopped at its iteration limit above its tolerance.
    #[error(
        "{solver} did not converge: residual {residual:.3e} above tolerance {tolerance:.1e} \
         after {iterations} iterations (raise --max-iter or loosen --tolerance)"
    )]
    NotConverged { solver: &'static str, iterations: usize, residual: f64, tolerance: f64 },
    /// Long work stopped early because its caller asked it to (a progress callback answered
    /// `ControlFlow::Break`, for instance on Ctrl-C).
    #[error("{what}: interrupted")]
    Interrupted { what: String },
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io { path: path.into(), source }
    }

    /// A content error in the file at `path`.
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Error::File { path: path.into(), reason: reason.into() }
    }

    /// An invalid value for `option` (a CLI flag such as `--load`, or a config key).
    pub fn invalid(option: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Invalid { option: option.into(), reason: reason.into() }
    }
}

/// The longest message line printed [characters].
pub const MESSAGE_CHARS: usize = 300;

/// A message as printed (the command line's error line, a Python exception): its first line,
/// [`escaped`], cut at [`MESSAGE_CHARS`] characters (a message may echo a value of any length).
pub fn one_line(message: &str) -> String {
    let line = escaped(message.lines().next().unwrap_or_default());
    if line.chars().count() <= MESSAGE_CHARS {
        line.into_owned()
    } else {
        line.chars().take(MESSAGE_CHARS).chain(['…']).collect()
    }
}

/// `text` with every character a terminal acts on, or that reorders what it shows, written as
/// an escape: C0 controls, DEL and C1 controls as `\x1b` (`\n`, `\r`, `\t` by name), the
/// Unicode bidirectional marks and overrides as `\u{202e}`. A file's content or an option's
/// value then cannot move the cursor, clear the screen or make a line read otherwise.
pub fn escaped(text: &str) -> Cow<'_, str> {
    if !text.chars().any(acts_on_terminal) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_ascii_control() => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c if acts_on_terminal(c) => {
                let _ = write!(out, "\\u{{{:x}}}", c as u32);
            }
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// Whether a terminal acts on `c` rather than showing it: a control character (C0, DEL, C1)
/// or one of the invisible marks that change the order in which text is shown (Unicode's
/// bidirectional formatting characters). All lie below U+10000.
pub fn acts_on_terminal(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// Result with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped() {
        assert!(matches!(escaped("plain µm – ok"), Cow::Borrowed(_)));
        assert_eq!(escaped("3 4\x1b[2J\rX"), "3 4\\x1b[2J\\rX");
        assert_eq!(escaped("a\tb\0\x7f"), "a\\tb\\x00\\x7f");
        assert_eq!(escaped("\u{9b}31m"), "\\u{9b}31m");
        assert_eq!(escaped("abc\u{202e}fed\u{2066}"), "abc\\u{202e}fed\\u{2066}");
    }

    #[test]
    fn a_message_is_one_escaped_short_line() {
        assert_eq!(one_line("error: t.txt: line 2: '4\x1b[2J\rX'\nsecond"), "error: t.txt: line 2: '4\\x1b[2J\\rX'");
        let long = one_line(&format!("error: {}", "\x07".repeat(400)));
        assert_eq!(long.chars().count(), MESSAGE_CHARS + 1);
        assert!(long.ends_with('…') && !long.contains('\x07'), "{long}");
    }
}
