//! What the text formats share: decoding, header lines, rows of numbers, lengths with units.
//!
//! Text readers allocate only in proportion to the numbers actually present in the file, never
//! from a count a header declares.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::borrow::Cow;

use ndarray::Array2;

use crate::quantity::metres_per;

/// The file as text: UTF-16 after its byte order mark (Windows exports of CSV tables), UTF-8
/// (a byte order mark dropped), or else Latin-1 (older Windows exports write `µ` as the single
/// byte 0xB5). A NUL character means binary data, not text.
pub(super) fn decode(bytes: &[u8]) -> Result<Cow<'_, str>, String> {
    if let Some(text) = utf16(bytes, false) {
        let text = text?;
        if text.contains('\0') {
            return Err("binary data (a NUL character in UTF-16 text) where text was expected".into());
        }
        return Ok(Cow::Owned(text));
    }
    let bytes = bytes.strip_prefix(UTF8_BOM).unwrap_or(bytes);
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(format!("binary data (a NUL byte at offset {at}) where text was expected"));
    }
    Ok(match std::str::from_utf8(bytes) {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    })
}

/// The leading bytes a format is sniffed from, as text; `None` for binary data. The head may
/// end inside a multi-byte character: that tail is dropped.
pub(super) fn decode_head(head: &[u8]) -> Option<Cow<'_, str>> {
    if let Some(text) = utf16(head, true) {
        return text.ok().filter(|t| !t.contains('\0')).map(Cow::Owned);
    }
    let head = head.strip_prefix(UTF8_BOM).unwrap_or(head);
    if head.contains(&0) {
        return None;
    }
    match std::str::from_utf8(head) {
        Ok(s) => Some(Cow::Borrowed(s)),
        Err(e) if e.error_len().is_none() => Some(Cow::Borrowed(std::str::from_utf8(&head[..e.valid_up_to()]).ok()?)),
        Err(_) => Some(Cow::Owned(head.iter().map(|&b| char::from(b)).collect())),
    }
}

const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// The text of UTF-16 `bytes` that start with a byte order mark (`None` without one); a `head`
/// may end inside a character, whose tail is then dropped.
fn utf16(bytes: &[u8], head: bool) -> Option<Result<String, String>> {
    let unit: fn([u8; 2]) -> u16 = match bytes {
        [0xFF, 0xFE, ..] => u16::from_le_bytes,
        [0xFE, 0xFF, ..] => u16::from_be_bytes,
        _ => return None,
    };
    if !head && bytes.len() % 2 == 1 {
        return Some(Err("UTF-16 text of an odd number of bytes: the file is cut".into()));
    }
    let mut units: Vec<u16> = bytes[2..].chunks_exact(2).map(|p| unit([p[0], p[1]])).collect();
    if head && units.last().is_some_and(|u| (0xD800..0xDC00).contains(u)) {
        units.pop();
    }
    Some(String::from_utf16(&units).map_err(|_| "invalid UTF-16 text (a lone surrogate)".to_string()))
}

/// A line shortened for an error message.
pub(super) fn excerpt(line: &str) -> String {
    let line = line.trim();
    let mut short: String = line.chars().take(40).collect();
    if short.len() < line.len() {
        short.push('…');
    }
    short
}

/// A number as text writes it (`1.5`, `-2e-9`, `1.8823e-008`, `NaN`).
pub(super) fn number(token: &str) -> Option<f64> {
    token.parse().ok()
}

/// `# Key: value`, `Key = value`, `% key : value`: the key and the value, trimmed. Comment
/// markers before the key are dropped; the first `:`, `=` or full-width colon separates.
pub(super) fn key_value(line: &str) -> Option<(&str, &str)> {
    let body = comment_body(line).unwrap_or(line);
    let at = body.find([':', '=', '：'])?;
    let sep_len = body[at..].chars().next().map_or(1, char::len_utf8);
    let key = body[..at].trim();
    if key.is_empty() || number(key).is_some() {
        return None;
    }
    Some((key, body[at + sep_len..].trim()))
}

/// The text of a comment line after its marker (`#`, `%`, `//`, `;`), or `None` if the line is
/// not a comment.
pub(super) fn comment_body(line: &str) -> Option<&str> {
    let t = line.trim_start();
    ["#", "%", "//", ";"].iter().find_map(|m| t.strip_prefix(m)).map(str::trim)
}

/// A line that may stand before the numbers of a table: a comment or a `key: value` line.
pub(super) fn is_header_line(line: &str) -> bool {
    comment_body(line).is_some() || key_value(line).is_some()
}

/// A length with its unit, `12.34 µm` or `12,34 µm`: the value in metres, or `None` when the
/// number or the unit is missing or the unit is not a length.
pub(super) fn length_in_metres(text: &str) -> Option<f64> {
    let text = text.trim();
    let split = text.find(char::is_whitespace).unwrap_or(text.len());
    let value = number(&text[..split]).or_else(|| number(&text[..split].replacen(',', ".", 1)))?;
    let metres = value * metres_per(text[split..].trim())?;
    (metres.is_finite() && metres > 0.0).then_some(metres)
}

/// How the numbers of a row are separated, decided once from a table's first row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Separators {
    /// Whitespace, `,` or `;` separate; `.` is the decimal mark.
    Plain,
    /// Whitespace or `;` separate; `,` is the decimal mark (a locale's export, `1,5\t-2,25`).
    DecimalComma,
}

impl Separators {
    /// The convention of a table whose first row of numbers is `line`, or `None` if that line
    /// is not a row of numbers under either.
    pub(super) fn detect(line: &str) -> Option<Self> {
        let comma_row: Vec<&str> = Separators::DecimalComma.tokens(line).collect();
        let decimal_comma = comma_row.len() >= 2
            && !line.contains('.')
            && line.contains(',')
            && comma_row.iter().all(|t| number(&t.replacen(',', ".", 1)).is_some());
        if decimal_comma {
            Some(Separators::DecimalComma)
        } else {
            let mut tokens = Separators::Plain.tokens(line).peekable();
            (tokens.peek().is_some() && tokens.all(|t| number(t).is_some())).then_some(Separators::Plain)
        }
    }

    fn tokens(self, line: &str) -> impl Iterator<Item = &str> {
        let split: fn(char) -> bool = match self {
            Separators::Plain => |c| c.is_whitespace() || c == ',' || c == ';',
            Separators::DecimalComma => |c| c.is_whitespace() || c == ';',
        };
        line.split(split).filter(|t| !t.is_empty())
    }

    /// The numbers of `line`, or the first token that is not one.
    pub(super) fn row(self, line: &str, out: &mut Vec<f64>) -> Result<(), String> {
        for t in self.tokens(line) {
            let v = match self {
                Separators::Plain => number(t),
                Separators::DecimalComma => number(&t.replacen(',', ".", 1)),
            };
            match v {
                Some(v) if v.is_infinite() => return Err(format!("'{}' is not a finite height", excerpt(t))),
                Some(v) => out.push(v),
                None => return Err(format!("'{}' is not a number", excerpt(t))),
            }
        }
        Ok(())
    }
}

/// What the head of a file shows of a table of numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct TableHead {
    /// Numbers in the first row (a lower bound when the row runs past the head).
    pub columns: usize,
    /// Whether the whole first row is in the head.
    pub complete: bool,
}

/// Whether `head` starts as a table of numbers, optionally after header lines, and how wide it
/// is. Binary data, prose and empty text are not tables.
pub(super) fn table_head(head: &[u8]) -> Option<TableHead> {
    let text = decode_head(head)?;
    let mut lines = text.split_inclusive('\n').filter(|l| !l.trim().is_empty());
    let first = lines.find(|l| !is_header_line(l))?;
    let complete = first.ends_with('\n');
    // A row cut by the end of the head may end in half a number: judge the tokens before it.
    let judged = if complete { first } else { first.rsplit_once([' ', '\t', ',', ';'])?.0 };
    let sep = Separators::detect(judged)?;
    Some(TableHead { columns: sep.tokens(judged).count(), complete })
}

/// Rows of numbers collected into a matrix, checking that every row has the same width.
#[derive(Debug, Default)]
pub(super) struct Rows {
    values: Vec<f64>,
    ncols: usize,
    nrows: usize,
    first_line: usize,
}

impl Rows {
    /// Append the numbers of `line` (1-based `line_no` for messages).
    pub(super) fn push(&mut self, sep: Separators, line_no: usize, line: &str) -> Result<(), String> {
        let before = self.values.len();
        sep.row(line, &mut self.values).map_err(|e| format!("line {line_no}: {e}"))?;
        let n = self.values.len() - before;
        if self.nrows == 0 {
            self.ncols = n;
            self.first_line = line_no;
        } else if n != self.ncols {
            return Err(format!(
                "line {line_no} holds {n} values but line {} holds {}: not a rectangular matrix",
                self.first_line, self.ncols
            ));
        }
        self.nrows += 1;
        Ok(())
    }

    pub(super) fn is_empty(&self) -> bool {
        self.nrows == 0
    }

    /// The matrix, shape (rows, columns); at least 2 × 2 to be a topography.
    pub(super) fn finish(self) -> Result<Array2<f64>, String> {
        if self.nrows < 2 || self.ncols < 2 {
            return Err(format!(
                "a {} × {} table of numbers is not a 2-D topography (at least 2 × 2 points needed)",
                self.ncols, self.nrows
            ));
        }
        Array2::from_shape_vec((self.nrows, self.ncols), self.values).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
pub(super) mod testing {
    //! Inputs for the readers' property tests: arbitrary text and mutated real files.

    use std::path::Path;

    use proptest::prelude::*;

    /// The bytes of a sample instrument file.
    pub fn sample(name: &str) -> Vec<u8> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name);
        std::fs::read(&path)
            .unwrap_or_else(|e| panic!("test data file {}: {e} (see tests/data/README.md)", path.display()))
    }

    /// One edit of a file: overwrite, insert or delete a byte, cut the tail, or repeat a span.
    #[derive(Debug, Clone)]
    pub enum Edit {
        Set(usize, u8),
        Insert(usize, u8),
        Delete(usize),
        Truncate(usize),
        Repeat(usize, usize),
    }

    /// Bytes typical of text topographies, so that edits make near-misses rather than noise.
    fn text_byte() -> impl Strategy<Value = u8> {
        prop_oneof![
            3 => prop::sample::select(b"0123456789.,;:=-+eE# \t\n*NaInf".to_vec()),
            1 => any::<u8>(),
        ]
    }

    pub fn edits() -> impl Strategy<Value = Vec<Edit>> {
        let edit = prop_oneof![
            (any::<usize>(), text_byte()).prop_map(|(i, b)| Edit::Set(i, b)),
            (any::<usize>(), text_byte()).prop_map(|(i, b)| Edit::Insert(i, b)),
            any::<usize>().prop_map(Edit::Delete),
            any::<usize>().prop_map(Edit::Truncate),
            (any::<usize>(), 1usize..64).prop_map(|(i, n)| Edit::Repeat(i, n)),
        ];
        prop::collection::vec(edit, 1..8)
    }

    pub fn apply(mut bytes: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
        for e in edits {
            let n = bytes.len().max(1);
            match *e {
                Edit::Set(i, b) if !bytes.is_empty() => bytes[i % n] = b,
                Edit::Insert(i, b) => bytes.insert(i % (bytes.len() + 1), b),
                Edit::Delete(i) if !bytes.is_empty() => {
                    bytes.remove(i % n);
                }
                Edit::Truncate(i) => bytes.truncate(i % n),
                Edit::Repeat(i, len) if !bytes.is_empty() => {
                    let start = i % n;
                    let span: Vec<u8> = bytes[start..(start + len).min(bytes.len())].to_vec();
                    bytes.splice(start..start, span);
                }
                _ => {}
            }
        }
        bytes
    }

    /// Arbitrary short text built from the characters text topographies use.
    pub fn texts() -> impl Strategy<Value = Vec<u8>> {
        prop::collection::vec(text_byte(), 0..400)
    }

    /// A reader's verdict is data or a one-line reason.
    pub fn one_line<T>(r: &Result<T, String>) -> bool {
        r.as_ref().err().is_none_or(|e| !e.is_empty() && !e.contains('\n'))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_comma_only_between_separated_numbers() {
        assert_eq!(Separators::detect("1,5\t-2,25"), Some(Separators::DecimalComma));
        assert_eq!(Separators::detect("1,2,3"), Some(Separators::Plain));
        assert_eq!(Separators::detect("1.5, 2.5"), Some(Separators::Plain));
        assert_eq!(Separators::detect("This is nonsense."), None);
        let mut v = Vec::new();
        Separators::DecimalComma.row("1,5\t-2,25", &mut v).unwrap();
        Separators::Plain.row("1.8823e-008;NaN, 3", &mut v).unwrap();
        assert_eq!(v[..3], [1.5, -2.25, 1.8823e-8]);
        assert!(v[3].is_nan());
        assert_eq!(v[4], 3.0);
        assert!(Separators::Plain.row("1 inf", &mut v).is_err());
    }

    #[test]
    fn lengths_with_units() {
        let close = |text: &str, metres: f64| (length_in_metres(text).unwrap() / metres - 1.0).abs() < 1e-15;
        assert!(close("12.34 µm", 12.34e-6));
        assert!(close("5678.9 nm", 5678.9e-9));
        assert!(close("12,5 mm", 12.5e-3));
        assert!(close("3 Å", 3e-10));
        assert_eq!(length_in_metres("10 px"), None);
        assert_eq!(length_in_metres("10"), None);
        assert_eq!(length_in_metres("-3 m"), None);
    }

    #[test]
    fn header_lines() {
        assert_eq!(key_value("# Width: 10 µm"), Some(("Width", "10 µm")));
        assert_eq!(key_value("Xscale = 1.0E-6"), Some(("Xscale", "1.0E-6")));
        assert_eq!(key_value("# Largeur : 3 µm"), Some(("Largeur", "3 µm")));
        assert_eq!(key_value("1 2 3"), None);
        assert!(is_header_line("# anything"));
        assert!(!is_header_line("This is nonsense. Should raise CannotDetectFileFormat."));
    }

    #[test]
    fn utf16_and_byte_order_marks() {
        let le: Vec<u8> = [0xFF, 0xFE].into_iter().chain("µm,1\n".encode_utf16().flat_map(u16::to_le_bytes)).collect();
        let be: Vec<u8> = [0xFE, 0xFF].into_iter().chain("µm,1\n".encode_utf16().flat_map(u16::to_be_bytes)).collect();
        assert_eq!(decode(&le).unwrap(), "µm,1\n");
        assert_eq!(decode(&be).unwrap(), "µm,1\n");
        assert_eq!(decode(b"\xEF\xBB\xBF1 2\n").unwrap(), "1 2\n");
        // A head cut inside a character keeps what came before it; a whole file may not be cut.
        assert_eq!(decode_head(&le[..le.len() - 1]).unwrap(), "µm,1");
        assert!(decode(&le[..le.len() - 1]).unwrap_err().contains("odd number of bytes"));
        let nul: Vec<u8> = [0xFF, 0xFE, b'1', 0, 0, 0].to_vec();
        assert!(decode(&nul).unwrap_err().contains("NUL character"));
        assert!(decode_head(&nul).is_none());
        assert!(decode(&[0xFF, 0xFE, 0x00, 0xD8]).unwrap_err().contains("lone surrogate"));
    }

    #[test]
    fn table_heads() {
        assert_eq!(table_head(b"# Width: 1 m\n1 2 3\n"), Some(TableHead { columns: 3, complete: true }));
        assert_eq!(table_head(b"1 2 3 4 5.2"), Some(TableHead { columns: 4, complete: false }));
        assert_eq!(table_head(b"prose, no numbers\n"), None);
        assert_eq!(table_head(b"1 2\0"), None);
    }
}
