//! The one error type of the library: each variant renders as a single line that names the
//! file or option at fault and the reason, as the CLI prints it. Messages echo file contents,
//! names and option values: [`one_line`] and [`escaped`] are the one way to print them, with
//! every character that a terminal would act on escaped.
//!
//! Imports nothing of the crate; must not import topography, contact, friction, study, report,
//! plot, shs, cli.

use std::borrow::Cow;
use std::fmt::Write;
use std::path::PathBuf;

/// Everything that can go wrong in asperity.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory at fault.
        path: PathBuf,
        /// What the operating system reported.
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its content is not what its format requires (truncated, corrupt,
    /// no topography in it, NaN heights, …).
    #[error("{}: {reason}", path.display())]
    File {
        /// The file at fault.
        path: PathBuf,
        /// What is wrong with its content.
        reason: String,
    },
    /// An option or parameter value that the physics or the grid cannot take.
    #[error("{option}: {reason}")]
    Invalid {
        /// The option, config key or parameter at fault (a CLI flag such as `--load`).
        option: String,
        /// Why its value cannot be taken.
        reason: String,
    },
    /// An iterative solver stopped at its iteration limit above its tolerance.
    #[error(
        "{solver} did not converge: residual {residual:.3e} above tolerance {tolerance:.1e} \
         after {iterations} iterations (raise --max-iter or loosen --tolerance; in a study file \
         [contact] max_iterations and tolerance)"
    )]
    NotConverged {
        /// The solver that stopped, as the message names it.
        solver: &'static str,
        /// Iterations done when it stopped.
        iterations: usize,
        /// Its last residual (dimensionless: the solver's own relative norm).
        residual: f64,
        /// The relative residual it had to reach.
        tolerance: f64,
    },
    /// Long work stopped early because its caller asked it to (a progress callback answered
    /// `ControlFlow::Break`, for instance on Ctrl-C).
    #[error("{what}: interrupted")]
    Interrupted {
        /// The work that stopped (a file, a study).
        what: String,
    },
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

/// The longest message line printed \[characters].
pub const MESSAGE_CHARS: usize = 300;

/// The fewest characters of a path or value that a shortened message keeps, its start and its
/// end (a file's name and extension, an option value's unit).
pub const KEPT_CHARS: usize = 40;

/// A message as printed (the command line's error line, a Python exception): the whole
/// message [`escaped`] (a newline in a value shows as `\n`), then, when longer than
/// [`MESSAGE_CHARS`], its longest words (the paths and values it echoes, which hold no space)
/// shortened in their middle, down to [`KEPT_CHARS`] each, so that the reason stays whole. Only
/// a message still too long once every word is short loses its middle.
pub fn one_line(message: &str) -> String {
    let line = escaped(message);
    let mut words: Vec<String> = line.split(' ').map(String::from).collect();
    let length = |words: &[String]| words.iter().map(|w| w.chars().count() + 1).sum::<usize>() - 1;
    let mut excess = length(&words).saturating_sub(MESSAGE_CHARS);
    while excess > 0 {
        let Some((i, n)) = words.iter().map(|w| w.chars().count()).enumerate().max_by_key(|(_, n)| *n) else { break };
        // A word cut once keeps more than KEPT_CHARS: never cut twice.
        if n <= KEPT_CHARS + 1 {
            break;
        }
        // The ellipsis takes one character.
        let kept = (n - excess - 1).max(KEPT_CHARS).min(n - 2);
        words[i] = middle_cut(&words[i], kept);
        excess = length(&words).saturating_sub(MESSAGE_CHARS);
    }
    let line = words.join(" ");
    if excess == 0 {
        line
    } else {
        // Many short words: their end is the reason's.
        middle_cut(&line, MESSAGE_CHARS - 1)
    }
}

/// `text` whole when it has at most `kept` characters, else its first and last characters,
/// `kept` in all, around an ellipsis.
pub fn middle_cut(text: &str, kept: usize) -> String {
    let n = text.chars().count();
    if n <= kept {
        return text.to_string();
    }
    let head = kept / 2;
    let tail = kept - head;
    text.chars().take(head).chain(['…']).chain(text.chars().skip(n - tail)).collect()
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
        assert_eq!(
            one_line("error: t.txt: line 2: '4\x1b[2J\rX'\nsecond"),
            "error: t.txt: line 2: '4\\x1b[2J\\rX'\\nsecond"
        );
        let long = one_line(&format!("error: {}", "\x07".repeat(400)));
        assert_eq!(long.chars().count(), MESSAGE_CHARS);
        assert!(long.contains('…') && !long.contains('\x07'), "{long}");
    }

    #[test]
    fn a_long_path_is_shortened_in_its_middle_and_the_reason_kept() {
        let path = format!("/data/{}/scan.npy", "d".repeat(5000));
        let line = one_line(&format!("error: {path}: No such file or directory (os error 2)"));
        assert_eq!(line.chars().count(), MESSAGE_CHARS);
        assert!(line.starts_with("error: /data/ddd"), "{line}");
        assert!(line.ends_with("ddd/scan.npy: No such file or directory (os error 2)"), "{line}");
        // Two long values: each keeps its start and end, the words between them stay.
        let two = one_line(&format!("error: {}: is not {}", "a".repeat(400), "b".repeat(400)));
        assert!(two.chars().count() <= MESSAGE_CHARS && two.contains(": is not b"), "{two}");
        // Many short words: the middle goes, the end stays.
        let words = one_line(&format!("error: {}the reason", "ab ".repeat(300)));
        assert_eq!(words.chars().count(), MESSAGE_CHARS);
        assert!(words.ends_with("ab the reason"), "{words}");
        assert_eq!(middle_cut("abcdef", 5), "ab…def");
        assert_eq!(middle_cut("abc", 5), "abc");
    }
}
