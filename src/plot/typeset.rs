//! Text with sub- and superscripts ("μ_S", "n^{tot}") typeset on a plotters drawing area.
//!
//! Must not import report, study, friction, contact or shs: typesetting knows only text.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontDesc, FontTransform};

use super::draw::DrawResult;
use super::style;

/// Pieces of typeset text: base line, subscript or superscript.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Level {
    Base,
    Sub,
    Super,
}

/// `text` cut into pieces at `_x` and `^x` (one character) or `_{…}` and `^{…}`, as TeX
/// writes sub- and superscripts: "μ_S", "N^μ/N", "n^{tot}".
fn pieces(text: &str) -> Vec<(String, Level)> {
    let mut out = Vec::new();
    let mut base = String::new();
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        let level = match c {
            '_' => Level::Sub,
            '^' => Level::Super,
            _ => {
                base.push(c);
                continue;
            }
        };
        let mut script = String::new();
        match chars.next() {
            Some('{') => script.extend(chars.by_ref().take_while(|d| *d != '}')),
            Some(d) => script.push(d),
            None => {
                base.push(c);
                continue;
            }
        }
        if !base.is_empty() {
            out.push((std::mem::take(&mut base), Level::Base));
        }
        out.push((script, level));
    }
    if !base.is_empty() {
        out.push((base, Level::Base));
    }
    out
}

fn piece_font(level: Level, size: f64) -> FontDesc<'static> {
    let size = if level == Level::Base { size } else { size * 0.72 };
    (style::FONT, size).into_font()
}

/// The width [px] of `text` typeset at `size`.
pub(super) fn typeset_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
) -> DrawResult<DB, i32> {
    let mut width = 0;
    for (t, level) in pieces(text) {
        width += area.estimate_text_size(&t, &piece_font(level, size).into_text_style(area))?.0 as i32;
    }
    Ok(width)
}

/// Draw `text` with its sub- and superscripts typeset (see [`pieces`]) at `pos` [px] on
/// `area`, centred across the line and anchored along it by `along`; reading upwards when
/// `vertical` (an axis name on the left).
pub(super) fn typeset<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    pos: (i32, i32),
    size: f64,
    along: HPos,
    vertical: bool,
) -> DrawResult<DB> {
    let total = typeset_width(area, text, size)?;
    let mut advance = match along {
        HPos::Left => 0,
        HPos::Center => -total / 2,
        HPos::Right => -total,
    };
    for (t, level) in pieces(text) {
        let shift = match level {
            Level::Base => 0,
            Level::Sub => (size * 0.28) as i32,
            Level::Super => -(size * 0.38) as i32,
        };
        let font = piece_font(level, size);
        let width = area.estimate_text_size(&t, &font.clone().into_text_style(area))?.0 as i32;
        let style = font.into_text_style(area).pos(Pos::new(HPos::Left, VPos::Center));
        if vertical {
            let style = style.transform(FontTransform::Rotate270);
            area.draw_text(&t, &style, (pos.0 + shift, pos.1 - advance))?;
        } else {
            area.draw_text(&t, &style, (pos.0 + advance, pos.1 + shift))?;
        }
        advance += width;
    }
    Ok(())
}
