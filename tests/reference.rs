//! The reference chapters that cannot drift from the program.
//!
//! `docs/commands.md` is every command's `--help` as the built `asperity` prints it: this test
//! renders it from the binary and fails when the file differs (`ASPERITY_WRITE_DOCS=1` writes
//! it instead). `docs/study.md`'s key tables are checked against the study file's parser,
//! [`StudyConfig::parse`]: every key it accepts is in the tables, every key in the tables is
//! accepted, and every default the tables state is the one the parser applies.
//!
//! The help is the same in a build with the `gpu` feature: only `--version` depends on it, and
//! it is not part of the reference.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use asperity::study::config::{StudyConfig, SurfaceSpec};
use asperity::topography::prepare::Preparation;

/// The command that regenerates `docs/commands.md`.
const REGENERATE: &str = "ASPERITY_WRITE_DOCS=1 cargo test --release --test reference";

fn docs(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs").join(name)
}

// ── docs/commands.md ────────────────────────────────────────────────────────────────────────

/// `asperity ARGS --help` on standard output (a pipe: no colours) with the terminal `columns`
/// wide.
fn help_at(args: &[String], columns: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(args)
        .arg("--help")
        .env("COLUMNS", columns)
        .output()
        .expect("asperity runs");
    let shown = format!("asperity {} --help", args.join(" "));
    assert!(out.status.success(), "{shown} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap_or_else(|e| panic!("{shown} printed no UTF-8: {e}"))
}

/// `asperity ARGS --help`, which must not depend on the terminal's width (clap wraps help only
/// with its `wrap_help` feature) nor name the build (the version and commit change with every
/// commit; `--version` says them).
fn help(args: &[String]) -> String {
    let text = help_at(args, "40");
    let shown = format!("asperity {} --help", args.join(" "));
    assert_eq!(text, help_at(args, "1000"), "{shown} depends on the terminal's width (COLUMNS)");
    assert!(!text.contains(asperity::VERSION), "{shown} names the version {}", asperity::VERSION);
    if asperity::COMMIT.len() >= 7 && asperity::COMMIT != "unknown" {
        let hash = asperity::COMMIT.trim_end_matches("-modified");
        assert!(!text.contains(hash), "{shown} names the commit {hash}");
    }
    text
}

/// The subcommands a help text lists under `Commands:`, in its order, without clap's own
/// `help` (which prints the help shown here).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| *l != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(String::from)
        .collect()
}

/// (`asperity topo info`, its help) for the command `args` and, depth first in the order of
/// the help's list, every subcommand under it.
fn commands(args: Vec<String>, found: &mut Vec<(String, String)>) {
    let text = help(&args);
    let subs = subcommands(&text);
    let title = std::iter::once("asperity".to_string()).chain(args.iter().cloned()).collect::<Vec<_>>().join(" ");
    found.push((title, text));
    for sub in subs {
        let mut deeper = args.clone();
        deeper.push(sub);
        commands(deeper, found);
    }
}

fn render_commands() -> String {
    let mut found = Vec::new();
    commands(Vec::new(), &mut found);
    let mut md = format!(
        "# Command reference\n\n\
         Every command's help, exactly as `asperity … --help` prints it. It is generated from the \
         program by `{REGENERATE}`: do not edit it by hand (without the variable, the test fails when the \
         two differ).\n"
    );
    for (title, text) in found {
        assert!(!text.contains("```"), "{title} --help contains a code fence");
        md.push_str(&format!("\n## {title}\n\n```text\n{}\n```\n", text.trim_end_matches('\n')));
    }
    md
}

/// `line`, cut to its first 80 characters.
fn short(line: &str) -> String {
    match line.char_indices().nth(80) {
        Some((i, _)) => format!("{}…", &line[..i]),
        None => line.to_string(),
    }
}

/// The header, or the first command whose section differs between `old` and `new`, with the
/// first line that differs.
fn first_difference(old: &str, new: &str) -> String {
    let sections = |text: &str| -> Vec<String> {
        let mut out = vec![String::new()];
        for line in text.lines() {
            if line.starts_with("## ") {
                out.push(String::new());
            }
            let last = out.last_mut().expect("one section at least");
            last.push_str(line);
            last.push('\n');
        }
        out
    };
    let (old, new) = (sections(old), sections(new));
    let name = |s: &str| s.lines().next().and_then(|l| l.strip_prefix("## ")).map(str::to_string);
    for i in 0..old.len().max(new.len()) {
        let (a, b) = (old.get(i).map_or("", |s| s.as_str()), new.get(i).map_or("", |s| s.as_str()));
        if a == b {
            continue;
        }
        let place = match (name(a), name(b)) {
            (_, Some(n)) if i > 0 => format!("`{n}`"),
            (Some(n), _) => format!("`{n}` (no longer a command)"),
            _ => "the header".to_string(),
        };
        let line = a.lines().zip(b.lines()).find(|(x, y)| x != y);
        let detail = match line {
            Some((x, y)) => format!(": the file has {:?}, the program prints {:?}", short(x), short(y)),
            None => String::new(),
        };
        return format!("{place}{detail}");
    }
    "nothing".to_string()
}

#[test]
fn the_command_reference_is_the_programs_help() {
    let rendered = render_commands();
    let path = docs("commands.md");
    if std::env::var("ASPERITY_WRITE_DOCS").as_deref() == Ok("1") {
        // A temporary beside it, renamed over it: a reader never sees half a file.
        let temporary = path.with_extension("md.partial");
        std::fs::write(&temporary, &rendered).expect("docs/ is writable");
        std::fs::rename(&temporary, &path).expect("docs/commands.md is replaceable");
        eprintln!("wrote {}", path.display());
        return;
    }
    let current =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("docs/commands.md: {e}; `{REGENERATE}` writes it"));
    assert!(
        current == rendered,
        "docs/commands.md differs from the program's help, first at {}; `{REGENERATE}` regenerates it",
        first_difference(&current, &rendered)
    );
}

#[test]
fn the_command_list_is_read_from_the_help() {
    let text = "Usage: x\n\nCommands:\n  info  Print\n  psd   Spectrum\n  help  Print this\n\nOptions:\n  -h\n";
    assert_eq!(subcommands(text), ["info", "psd"]);
    assert!(subcommands("Usage: x\n\nOptions:\n  -h, --help\n").is_empty());
    let old = "# R\n\n## asperity\n\na\n\n## asperity run\n\nb\nc\n";
    assert_eq!(first_difference(old, old), "nothing");
    let new = old.replace("c\n", "d\n");
    assert_eq!(first_difference(old, &new), "`asperity run`: the file has \"c\", the program prints \"d\"");
    assert!(first_difference(old, &old.replace("# R", "# S")).starts_with("the header"));
}

// ── docs/study.md ───────────────────────────────────────────────────────────────────────────

/// A key no table accepts: its error lists the keys the table does.
const BOGUS: &str = "no_such_key";

/// A study file with `entry` (`key = value`, or nothing) placed in the table a key table of
/// docs/study.md documents. Several studies for one table place the same keys in different
/// places: a topography and its wafer (the same table, whose `name` and `wafer` the study's
/// check refuses in a wafer), a synthetic and a measured cap.
fn studies(table: &str, entry: &str) -> Vec<String> {
    let line = if entry.is_empty() { String::new() } else { format!("{entry}\n") };
    let inline = if entry.is_empty() { String::new() } else { format!(", {entry}") };
    let measured = "[[topography]]\nname = \"a\"\nfile = \"a.npy\"\n";
    let synthetic = |extra: &str| {
        format!(
            "[[topography]]\nname = \"a\"\nsynthetic = {{ size_m = [1e-5, 1e-5], grid = [8, 8], seed = 1, {extra} }}\n"
        )
    };
    let roughness = "roughness = { hurst = 0.8, rms_height_m = 1e-9 }";
    match table {
        "sections" => vec![line],
        "topography" => vec![format!("{measured}{line}"), format!("{measured}wafer = {{ file = \"w.npy\"{inline} }}\n")],
        "synthetic" => vec![format!(
            "[[topography]]\nname = \"a\"\nsynthetic = {{ size_m = [1e-5, 1e-5], grid = [8, 8], {roughness}{inline} }}\n"
        )],
        "roughness" => vec![synthetic(&format!("roughness = {{ hurst = 0.8, rms_height_m = 1e-9{inline} }}"))],
        "cap" => vec![
            synthetic(&format!("cap = {{ radius_m = 1e-3{inline} }}")),
            format!("{measured}cap = {{ radius_m = \"1.5 mm\"{inline} }}\n"),
        ],
        "crop" => vec![format!("{measured}crop = {{ x = [0, 1e-6], y = [0, 1e-6]{inline} }}\n")],
        "material" | "contact" | "loads" | "model" | "output" | "limits" => vec![format!("[{table}]\n{line}")],
        "adhesion" => vec![format!("[contact]\nadhesion = {{ work = \"50 mJ/m2\", range = \"1 nm\"{inline} }}\n")],
        "law" => vec![format!("[[law]]\npreset = \"hold 100 s\"\n{line}")],
        other => panic!("docs/study.md has a key table `{other}` this test does not know: add it to `studies`"),
    }
}

/// Every table docs/study.md must have.
const TABLES: [&str; 14] = [
    "sections",
    "topography",
    "synthetic",
    "roughness",
    "cap",
    "crop",
    "material",
    "contact",
    "adhesion",
    "loads",
    "law",
    "model",
    "output",
    "limits",
];

/// One row of a key table: key | unit | default | allowed values | meaning.
#[derive(Debug)]
struct Row {
    key: String,
    default: String,
    allowed: String,
}

/// The key tables of docs/study.md, by name: the rows between `<!-- study-keys: NAME begin -->`
/// and `<!-- study-keys: NAME end -->`.
fn key_tables(md: &str) -> Vec<(String, Vec<Row>)> {
    let mut tables: Vec<(String, Vec<Row>)> = Vec::new();
    let mut open: Option<String> = None;
    for (n, line) in md.lines().enumerate() {
        let marker = line.trim().strip_prefix("<!-- study-keys: ").and_then(|l| l.strip_suffix(" -->"));
        if let Some(marker) = marker {
            match (marker.split_once(' '), &open) {
                (Some((name, "begin")), None) => {
                    open = Some(name.to_string());
                    tables.push((name.to_string(), Vec::new()));
                }
                (Some((name, "end")), Some(o)) if name == o => open = None,
                _ => panic!("docs/study.md:{}: unexpected marker {line:?}", n + 1),
            }
            continue;
        }
        let Some(rows) = open.as_ref().and(tables.last_mut()) else { continue };
        if !line.starts_with('|') || line.starts_with("|--") || line.starts_with("| key ") {
            continue;
        }
        let cells = cells(line);
        assert_eq!(cells.len(), 5, "docs/study.md:{}: a key row has 5 cells: {line:?}", n + 1);
        let key = cells[0].trim_matches('`').trim_matches(['[', ']']).to_string();
        assert!(
            !key.is_empty() && key.chars().all(|c| c.is_ascii_lowercase() || c == '_'),
            "docs/study.md:{}: {line:?}",
            n + 1
        );
        rows.1.push(Row { key, default: cells[2].clone(), allowed: cells[3].clone() });
    }
    assert!(open.is_none(), "docs/study.md: the key table `{}` has no end marker", open.unwrap_or_default());
    tables
}

/// The cells of a Markdown table row, `\|` kept as `|`.
fn cells(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut chars = line.trim().trim_start_matches('|').chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => out.last_mut().unwrap().push(chars.next().unwrap()),
            '|' => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    if out.last().is_some_and(|c| c.trim().is_empty()) {
        out.pop();
    }
    out.into_iter().map(|c| c.trim().to_string()).collect()
}

/// The keys the parser accepts in the table `study` places [`BOGUS`] in, as its error for the
/// unknown key lists them (serde's "unknown field `…`, expected one of `a`, `b`"). Every table
/// of the study file refuses unknown keys, so the list is the parser's own: none is flattened
/// or an untagged enum of tables (`plastic` is an untagged value, with no keys), `synthetic`
/// and `cap` are read as a table whose `_m` strings become lengths and then as their structs,
/// and `roughness` through its spelling in the file, each refusing unknown keys.
fn accepted_keys(study: &str) -> BTreeSet<String> {
    let e = StudyConfig::parse(study, "study.toml").expect_err("an unknown key is refused").to_string();
    let listed = e
        .split_once(&format!("unknown field `{BOGUS}`, expected "))
        .unwrap_or_else(|| panic!("the parser's error lists no keys: {e}\nfor the study:\n{study}"))
        .1;
    listed.split('`').skip(1).step_by(2).map(String::from).collect()
}

/// A parsed study as it acts: a measured surface's levelling is taken where it is applied (the
/// parser keeps `detrend` unset and [`SurfaceSpec::detrend`] levels a plane), so that a
/// default the parser leaves to the preparation compares equal to the value written out.
fn as_applied(mut c: StudyConfig) -> (StudyConfig, Vec<Preparation>) {
    fn surface(s: &mut SurfaceSpec, preparations: &mut Vec<Preparation>) {
        preparations.push(s.preparation(None, Default::default()));
        s.detrend = None;
        if let Some(w) = &mut s.wafer {
            surface(w, preparations);
        }
    }
    let mut preparations = Vec::new();
    c.topographies.iter_mut().for_each(|t| surface(t, &mut preparations));
    (c, preparations)
}

/// A table's default cell: `` `value` `` as the study file writes it (checked), *all listed*
/// (the list of every backticked value of the allowed cell, checked), or words for a default
/// that is no value (unchecked), `—` for none.
fn stated_default(row: &Row) -> Option<String> {
    let d = row.default.as_str();
    if d == "*all listed*" {
        let values: Vec<&str> = row.allowed.split('`').skip(1).step_by(2).collect();
        return Some(format!("[{}]", values.join(", ")));
    }
    let literal = d.strip_prefix('`').and_then(|d| d.strip_suffix('`'));
    match literal {
        Some(v) => Some(v.to_string()),
        None => {
            assert!(d == "—" || (d.starts_with('*') && d.ends_with('*')), "a default is `value`, *words* or —: {d:?}");
            None
        }
    }
}

#[test]
fn the_study_reference_has_every_key_the_parser_accepts_and_its_defaults() {
    let md = std::fs::read_to_string(docs("study.md")).expect("docs/study.md");
    let tables = key_tables(&md);
    let names: Vec<&str> = tables.iter().map(|(n, _)| n.as_str()).collect();
    for t in TABLES {
        assert!(names.contains(&t), "docs/study.md has no key table `{t}` (<!-- study-keys: {t} begin -->)");
    }
    let mut problems = Vec::new();
    for (name, rows) in &tables {
        let documented: BTreeSet<String> = rows.iter().map(|r| r.key.clone()).collect();
        assert_eq!(documented.len(), rows.len(), "docs/study.md: a key is listed twice in `{name}`");
        for study in studies(name, &format!("{BOGUS} = 1")) {
            let accepted = accepted_keys(&study);
            let missing: Vec<_> = accepted.difference(&documented).collect();
            let unknown: Vec<_> = documented.difference(&accepted).collect();
            if !missing.is_empty() {
                problems.push(format!("table `{name}` lacks the keys {missing:?} the parser accepts"));
            }
            if !unknown.is_empty() {
                problems.push(format!("table `{name}` lists the keys {unknown:?} the parser refuses"));
            }
        }
        for row in rows {
            let Some(value) = stated_default(row) else { continue };
            for (without, with) in studies(name, "").into_iter().zip(studies(name, &format!("{} = {value}", row.key))) {
                let written = with.trim().replace('\n', "; ");
                let without = StudyConfig::parse(&without, "study.toml").unwrap_or_else(|e| panic!("{e}\n{without}"));
                match StudyConfig::parse(&with, "study.toml") {
                    Err(e) => problems.push(format!("table `{name}`: `{}`'s default {value} is refused: {e}", row.key)),
                    Ok(c) => {
                        if as_applied(c) != as_applied(without) {
                            problems.push(format!(
                                "table `{name}`: `{}`'s default is not {value}: the study `{written}` does not read \
                                 as it does without the key",
                                row.key
                            ))
                        }
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "docs/study.md disagrees with the study file's parser:\n{}", problems.join("\n"));
}

/// The checks above can fail: a key table that lacks a key, names one the parser refuses, or
/// states a wrong default is caught.
#[test]
fn the_study_check_catches_a_wrong_table() {
    let accepted = accepted_keys(&studies("limits", &format!("{BOGUS} = 1"))[0]);
    assert_eq!(accepted, BTreeSet::from(["max_points".to_string()]));
    let accepted = accepted_keys(&studies("cap", &format!("{BOGUS} = 1"))[1]);
    assert_eq!(accepted, BTreeSet::from(["radius_m".to_string(), "shape".to_string()]));
    let md = "<!-- study-keys: limits begin -->\n| key | unit | default | allowed | meaning |\n|---|---|---|---|---|\n\
              | `max_points` | points | `268435455` | ≥ 4 | the largest grid |\n<!-- study-keys: limits end -->\n";
    let tables = key_tables(md);
    assert_eq!(tables.len(), 1);
    let row = &tables[0].1[0];
    assert_eq!((row.key.as_str(), stated_default(row).as_deref()), ("max_points", Some("268435455")));
    let parse = |t: &str| as_applied(StudyConfig::parse(t, "s.toml").unwrap());
    let [without, with] = [studies("limits", ""), studies("limits", "max_points = 268435455")].map(|s| s[0].clone());
    assert_ne!(parse(&without), parse(&with), "a wrong default is told apart");
    let [without, with] =
        [studies("topography", ""), studies("topography", "detrend = \"plane\"")].map(|s| s[0].clone());
    assert_eq!(parse(&without), parse(&with), "a plane is a measured surface's levelling by default");
    let with = studies("topography", "detrend = \"mean\"")[0].clone();
    assert_ne!(parse(&without), parse(&with));
    assert_eq!(cells("| `a` | m | `\"x\"` | `\"p\"` or `\"q\"` \\| r | s |").len(), 5);
}

/// The study files the chapter shows are valid.
#[test]
fn the_study_reference_examples_parse() {
    let md = std::fs::read_to_string(docs("study.md")).expect("docs/study.md");
    let mut blocks = md.split("```toml\n").skip(1).map(|b| b.split("```").next().unwrap_or_default()).peekable();
    assert!(blocks.peek().is_some(), "docs/study.md shows no study file");
    for block in blocks {
        if let Err(e) = StudyConfig::parse(block, "docs/study.md example") {
            panic!("{e}\nin the example:\n{block}");
        }
    }
}
