//! Places in the study file: key paths (`topography[1].wafer.file`), the line and column of
//! a key, and the one-line reason an error gives there. The sections' checks return a key
//! path and a reason ([`Checked`]); [`super::StudyConfig::parse`] turns it into a located
//! error.
//!
//! It must not import the study's sections or runner, nor `plot`, `report`, `cli` or
//! `python`.

use std::ops::Range;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::Error;

/// What a section's check finds: nothing, or the key path of the first wrong value and the
/// reason.
pub(super) type Checked = std::result::Result<(), (Vec<Segment>, String)>;

/// The error of the value at `path`, for `reason`.
pub(super) fn at(path: &[Segment], reason: String) -> Checked {
    Err((path.to_vec(), reason))
}

/// One step of a key path: a key, or an index into an array (of tables).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Segment {
    Key(String),
    Index(usize),
}

pub(super) fn key(k: &str) -> Segment {
    Segment::Key(k.to_string())
}

/// `topography[1].wafer.file`.
pub(super) fn render(path: &[Segment]) -> String {
    let mut out = String::new();
    for s in path {
        match s {
            Segment::Key(k) if out.is_empty() => out.push_str(k),
            Segment::Key(k) => {
                out.push('.');
                out.push_str(k);
            }
            Segment::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// The key path of the most deeply nested key or value at byte `offset`.
pub(super) fn path_at(root: &DeTable, offset: usize) -> Vec<Segment> {
    fn visit(value: &DeValue, offset: usize, path: &mut Vec<Segment>, best: &mut Vec<Segment>) {
        if let Some(table) = value.as_table() {
            for (k, v) in table.iter() {
                path.push(Segment::Key(k.get_ref().to_string()));
                if k.span().contains(&offset) || v.span().contains(&offset) {
                    note(path, best);
                }
                visit(v.get_ref(), offset, path, best);
                path.pop();
            }
        } else if let Some(array) = value.as_array() {
            for (i, item) in array.iter().enumerate() {
                path.push(Segment::Index(i));
                if item.span().contains(&offset) {
                    note(path, best);
                }
                visit(item.get_ref(), offset, path, best);
                path.pop();
            }
        }
    }
    fn note(path: &[Segment], best: &mut Vec<Segment>) {
        if path.len() > best.len() {
            *best = path.to_vec();
        }
    }
    let mut best = Vec::new();
    visit(&DeValue::Table(root.clone()), offset, &mut Vec::new(), &mut best);
    best
}

/// The span of the key (or array item) at `path`, or of the deepest part of it present.
pub(super) fn span_of(root: &DeTable, path: &[Segment]) -> Option<Range<usize>> {
    let mut span = None;
    let mut node: Option<&DeValue> = None;
    for seg in path {
        let next: Option<(Range<usize>, &Spanned<DeValue>)> = match (seg, node) {
            (Segment::Key(k), None) => root.get(k.as_str()).map(|v| (key_span(root, k), v)),
            (Segment::Key(k), Some(v)) => v.as_table().and_then(|t| t.get(k.as_str()).map(|x| (key_span(t, k), x))),
            (Segment::Index(i), Some(v)) => v.as_array().and_then(|a| a.get(*i)).map(|x| (x.span(), x)),
            (Segment::Index(_), None) => None,
        };
        let Some((s, v)) = next else { break };
        span = Some(s);
        node = Some(v.get_ref());
    }
    span
}

fn key_span(table: &DeTable, k: &str) -> Range<usize> {
    table.iter().find(|(key, _)| key.get_ref() == k).map(|(key, _)| key.span()).unwrap_or(0..0)
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

pub(super) fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The reason of an error from the library's checks, without the CLI option it names.
pub(super) fn reason_of(e: Error) -> String {
    match e {
        Error::Invalid { option, reason } if option.starts_with("--") => reason,
        Error::Invalid { option, reason } => format!("{option}: {reason}"),
        other => other.to_string(),
    }
}
