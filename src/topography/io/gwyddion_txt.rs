//! Gwyddion's ASCII export ("Export Text", `.txt`) with its informational header:
//!
//! ```text
//! # Channel: My Channel Name
//! # Width: 12.34 µm
//! # Height: 5678.9 nm
//! # Value units: m
//! 1    1.5    3           (tab-separated)
//! ```
//!
//! Gwyddion translates the four labels into the language of its user interface, so they are
//! recognised by position: channel title, width and height with their units, then the unit of
//! the values, which are written in that unit (normally the base unit, `m`). A locale with a
//! decimal comma writes `12,34 µm` and `1,5`. "Concatenate exports of all images" writes one
//! such block per channel, separated by a blank line. A Gwyddion export without the header is a
//! plain [`super::matrix`].
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::reading::{Channel, Format};
use super::text::{self, Rows, Separators};
use crate::quantity::metres_per;

pub struct GwyddionTxt;

/// The first three labels as Gwyddion writes them, in English and in its translations.
const CHANNEL: &[&str] = &["Channel", "Kanál", "Kanal", "Canal", "Canale", "채널", "Канал"];
const WIDTH: &[&str] = &["Width", "Šířka", "Breite", "Anchura", "Largeur", "Larghezza", "폭", "Ширина"];
const HEIGHT: &[&str] = &["Height", "Výška", "Höhe", "Altura", "Hauteur", "Altezza", "높이", "Высота"];

impl Format for GwyddionTxt {
    fn name(&self) -> &'static str {
        "gwyddion-txt"
    }

    /// None: a `.txt` file is told apart by its header alone, and without one it is a plain
    /// matrix.
    fn extensions(&self) -> &'static [&'static str] {
        &[]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        let Some(text) = text::decode_head(head) else { return false };
        let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).take(5).collect();
        lines.len() == 5 && block_header(&lines[..4]).is_ok()
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let text = text::decode(bytes)?;
        let mut lines =
            text.lines().enumerate().map(|(i, l)| (i + 1, l)).filter(|(_, l)| !l.trim().is_empty()).peekable();
        let mut channels = Vec::new();
        while lines.peek().is_some() {
            let head: Vec<(usize, &str)> = lines.by_ref().take(4).collect();
            let texts: Vec<&str> = head.iter().map(|&(_, l)| l).collect();
            let header = block_header(&texts).map_err(|e| format!("line {}: {e}", head[0].0))?;
            let mut rows = Rows::default();
            let mut sep = None;
            while let Some(&(line_no, line)) = lines.peek() {
                if text::comment_body(line).is_some() {
                    break;
                }
                let s = *sep.get_or_insert(Separators::detect(line).unwrap_or(Separators::Plain));
                rows.push(s, line_no, line)?;
                lines.next();
            }
            if rows.is_empty() {
                return Err(format!("channel '{}' (line {}) has no values", text::excerpt(&header.title), head[0].0));
            }
            let mut data = rows.finish().map_err(|e| format!("channel '{}': {e}", text::excerpt(&header.title)))?;
            let scale = header.unit.as_deref().and_then(metres_per);
            if let Some(s) = scale {
                data.mapv_inplace(|h| h * s);
            }
            channels.push(Channel {
                name: header.title,
                data,
                physical_size: header.size,
                is_height: header.unit.is_none() || scale.is_some(),
                unit: header.unit,
            });
        }
        if channels.is_empty() {
            return Err("no topography in it: the file is empty".into());
        }
        Ok(channels)
    }
}

/// One channel's header block.
struct BlockHeader {
    title: String,
    /// Physical size (width, height) [m]; `None` when the lateral unit is not a length.
    size: Option<(f64, f64)>,
    /// Unit of the values; `None` for dimensionless values.
    unit: Option<String>,
}

/// The four header lines of a block, recognised by their position and the first three labels.
fn block_header(lines: &[&str]) -> Result<BlockHeader, String> {
    let field = |i: usize, labels: &[&str]| -> Result<&str, String> {
        let line = lines.get(i).copied().unwrap_or("");
        let (label, value) = text::comment_body(line)
            .and_then(text::key_value)
            .ok_or_else(|| format!("'{}' is not a '# Label: value' header line", text::excerpt(line)))?;
        if labels.is_empty() || labels.contains(&label) {
            Ok(value)
        } else {
            Err(format!("'{}' stands where Gwyddion's export writes '{}'", text::excerpt(label), labels[0]))
        }
    };
    let title = field(0, CHANNEL)?.to_string();
    let (width, height) = (field(1, WIDTH)?, field(2, HEIGHT)?);
    let unit = field(3, &[])?;
    let number_with_unit = |v: &str| v.split_whitespace().next().and_then(|n| text::number(&n.replacen(',', ".", 1)));
    for v in [width, height] {
        if number_with_unit(v).is_none() {
            return Err(format!("'{}' is not a size", text::excerpt(v)));
        }
    }
    let size = text::length_in_metres(width).zip(text::length_in_metres(height));
    Ok(BlockHeader { title, size, unit: (!unit.is_empty()).then(|| unit.to_string()) })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    #[test]
    fn english_export() {
        let bytes = testing::sample("gwyddion-export-english.txt");
        assert!(GwyddionTxt.sniff(&bytes));
        let ch = GwyddionTxt.read(&bytes).unwrap();
        assert_eq!(ch.len(), 1);
        assert_eq!(ch[0].name, "My Channel Name");
        assert_eq!(ch[0].data.dim(), (4, 3));
        assert_eq!(ch[0].data.row(1).to_vec(), [-2.0, -3.0, -6.0]);
        let (lx, ly) = ch[0].physical_size.unwrap();
        assert!((lx / 12.34e-6 - 1.0).abs() < 1e-12 && (ly / 5678.9e-9 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn translated_decimal_comma_and_concatenated() {
        let file = "# Kanal: Höhe\n# Breite: 2,5 µm\n# Höhe: 1,25 µm\n# Value units: m\n1,5\t-2\n3\t4,25\n\n\
                    # Kanal: Phase\n# Breite: 2,5 µm\n# Höhe: 1,25 µm\n# Value units: deg\n1\t2\n3\t4\n";
        assert!(GwyddionTxt.sniff(file.as_bytes()));
        let ch = GwyddionTxt.read(file.as_bytes()).unwrap();
        assert_eq!(ch.len(), 2);
        assert_eq!(ch[0].data.as_slice().unwrap(), &[1.5, -2.0, 3.0, 4.25]);
        let (lx, ly) = ch[0].physical_size.unwrap();
        assert!((lx / 2.5e-6 - 1.0).abs() < 1e-15 && (ly / 1.25e-6 - 1.0).abs() < 1e-15);
        assert!(ch[0].is_height && !ch[1].is_height);
        assert_eq!(ch[1].unit.as_deref(), Some("deg"));
    }

    #[test]
    fn other_headers_are_not_gwyddion() {
        assert!(!GwyddionTxt.sniff(&testing::sample("xyz-1.txt")));
        assert!(!GwyddionTxt.sniff(b"# Sample: A\n# Speed: 2 um/s\n# Height: 1 um\n# Value units: m\n1 2\n"));
        let e = GwyddionTxt.read(b"# Channel: a\n# Width: 1 um\n# Height: 1 um\n# Value units: m\n").unwrap_err();
        assert!(e.contains("channel 'a' (line 1) has no values"), "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn arbitrary_text_never_panics(bytes in testing::texts()) {
            prop_assert!(testing::one_line(&GwyddionTxt.read(&bytes)));
        }

        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("gwyddion-export-english.txt"), &edits);
            prop_assert!(testing::one_line(&GwyddionTxt.read(&bytes)));
        }
    }
}
