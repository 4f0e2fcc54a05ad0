//! Properties of the text readers (proptest): any text, in any text format, ends in channels or
//! in a one-line error of a few hundred characters at most, never a panic; a matrix and an
//! x y z point list written from known heights read back exactly, whatever the separators and
//! the order of the points.

use std::path::Path;

use asperity::topography::io::read_channels;
use proptest::prelude::*;

const TEXT_FORMATS: [&str; 5] = ["matrix", "xyz", "gwyddion-txt", "gsf", "sdf"];

/// Read `text` from a file in `dir` as `format`.
fn read_as(dir: &Path, format: &str, text: &[u8]) -> Result<Vec<ndarray::Array2<f64>>, String> {
    let path = dir.join("surface.txt");
    std::fs::write(&path, text).unwrap();
    read_channels(&path, Some(format)).map(|(_, c)| c.into_iter().map(|c| c.data).collect()).map_err(|e| e.to_string())
}

fn one_short_line(e: &str) -> Result<(), TestCaseError> {
    prop_assert!(!e.contains('\n'), "several lines: {e}");
    prop_assert!(e.chars().count() <= 400, "{} characters: {}", e.chars().count(), &e[..200]);
    Ok(())
}

/// Lines of what text exports hold: numbers, separators, comments, `key = value` headers.
fn texty() -> impl Strategy<Value = String> {
    let token = prop_oneof![
        "-?[0-9]{1,3}(\\.[0-9]{0,4})?([eE][-+]?[0-9]{1,3})?",
        Just("NaN".to_string()),
        Just("inf".to_string()),
        "[ \t,;]{1,2}",
        Just("\n".to_string()),
        Just("\r\n".to_string()),
        "(# |% |// )?[A-Za-z ]{1,12}(:|=) ?[0-9.]{0,6} ?(nm|um|µm|m|V|rad)?\n",
        "[\\x00-\\x7f]{1,4}",
    ];
    proptest::collection::vec(token, 0..120).prop_map(|t| t.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn any_text_is_read_or_refused_in_one_line(text in texty(), format in 0usize..TEXT_FORMATS.len()) {
        let dir = tempfile::tempdir().unwrap();
        if let Err(e) = read_as(dir.path(), TEXT_FORMATS[format], text.as_bytes()) {
            one_short_line(&e)?;
        }
    }

    #[test]
    fn a_matrix_reads_back_exactly(
        values in proptest::collection::vec(-1e3f64..1e3, 4..64),
        columns in 2usize..8,
        sep in prop_oneof![Just(" "), Just("\t"), Just(", "), Just(";"), Just("  ")],
        crlf in any::<bool>(),
    ) {
        let rows = values.len() / columns;
        prop_assume!(rows >= 2);
        let values = &values[..rows * columns];
        let newline = if crlf { "\r\n" } else { "\n" };
        let text: String = values
            .chunks(columns)
            .map(|row| row.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(sep) + newline)
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let data = read_as(dir.path(), "matrix", text.as_bytes()).map_err(TestCaseError::fail)?;
        prop_assert_eq!(data[0].dim(), (rows, columns));
        prop_assert_eq!(data[0].iter().copied().collect::<Vec<_>>(), values.to_vec());
    }

    #[test]
    fn xyz_points_in_any_order_read_back_on_their_grid(
        nx in 2usize..7, ny in 2usize..7,
        step in (1e-9f64..1e-6, 1e-9f64..1e-6),
        origin in (-1e-5f64..1e-5, -1e-5f64..1e-5),
        seed in any::<u64>(),
    ) {
        let z = |i: usize, j: usize| (i as f64 - 2.5) * 1e-9 + (j * j) as f64 * 3e-10;
        let mut points: Vec<(usize, usize)> = (0..ny).flat_map(|j| (0..nx).map(move |i| (i, j))).collect();
        // A deterministic shuffle from the seed.
        let mut state = seed | 1;
        for k in (1..points.len()).rev() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            points.swap(k, (state % (k as u64 + 1)) as usize);
        }
        let text: String = points
            .iter()
            .map(|&(i, j)| {
                format!("{:e} {:e} {:e}\n", origin.0 + i as f64 * step.0, origin.1 + j as f64 * step.1, z(i, j))
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let data = read_as(dir.path(), "xyz", text.as_bytes()).map_err(TestCaseError::fail)?;
        prop_assert_eq!(data[0].dim(), (ny, nx));
        for ((j, i), v) in data[0].indexed_iter() {
            prop_assert_eq!(*v, z(i, j));
        }
    }
}

/// One very long token or line, in every text format: refused (or read) with a short message.
#[test]
fn long_tokens_are_not_quoted_whole() {
    let dir = tempfile::tempdir().unwrap();
    let long_number = "9".repeat(100_000);
    let cases = [
        "x".repeat(100_000),
        format!("1 2\n3 {long_number}x\n"),
        format!("# {}: 1\n1 2\n3 4\n", "k".repeat(100_000)),
        format!("1 2 3\n{long_number} 4 5\n"),
        "[".repeat(100_000),
    ];
    for text in &cases {
        for format in TEXT_FORMATS {
            if let Err(e) = read_as(dir.path(), format, text.as_bytes()) {
                assert!(!e.contains('\n') && e.chars().count() <= 400, "{format}: {} characters", e.chars().count());
            }
        }
    }
}
