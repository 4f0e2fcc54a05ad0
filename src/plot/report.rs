//! The study's report: one self-contained HTML page (inline style, relative links to the
//! images, nothing fetched from elsewhere) with the parameters, the friction laws, a table of
//! the friction drop per law and load, and every figure drawn with its caption.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use std::fmt::Write as _;
use std::path::Path;

use super::shared::{by_load, signed, spread, stem, Drawn, FigureInput};
use crate::error::Result;
use crate::friction::{FrictionLaw, PRESETS};
use crate::quantity::{show, FORCE, LENGTH};
use crate::study::{law_name, FigureKind, Row, Sharing};

/// What each figure is, and which figure of the paper it corresponds to.
fn heading(kind: FigureKind) -> (&'static str, &'static str) {
    match kind {
        FigureKind::FrictionDrop => ("Friction drop vs normal load", "Fig. 2"),
        FigureKind::FrictionDropSharing => {
            ("Friction drop under equal and elastic sharing", "the limit the paper names")
        }
        FigureKind::StaticDynamicCoefficients => ("Static and dynamic friction coefficients", "Fig. S1"),
        FigureKind::Resolution => ("Friction drop vs pixel size", "the element size"),
        FigureKind::HoldTime => ("Friction drop vs hold time", "aging, Fig. 2's two hold times"),
        FigureKind::StressRatioHistograms => ("Distributions of the local stress ratio", "Fig. 4b–e"),
        FigureKind::PressureDistribution => ("Distribution of the local normal stress", "Fig. 3"),
        FigureKind::ContactMaps => ("Contact maps", "Fig. S4"),
        FigureKind::ClassMap => ("Element classes at the critical state", "Fig. 4f"),
        FigureKind::ClassFractions => ("Force shares of the element classes", "Fig. 4g"),
        FigureKind::FrictionCurve => ("Friction–displacement curve", "Fig. 4a"),
        FigureKind::StressRatioSnapshots => ("Stress-ratio snapshots", "Fig. S6"),
        FigureKind::Movies => ("Movies of the stress ratio", "supplemental movies"),
    }
}

/// Text escaped for HTML.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Whether `law` is one of the illustrative presets, unchanged.
fn is_preset(law: &FrictionLaw) -> bool {
    PRESETS
        .iter()
        .any(|(name, mu_s, mu_d)| law.name.as_deref() == Some(*name) && law.mu_s == *mu_s && law.mu_d == *mu_d)
}

/// The page's look. Figures are drawn up to 1800 px wide for a text column of 1100 px: each is
/// shown as wide as the window allows (centred on the column), and a click opens it at full size.
const STYLE: &str = "body{font-family:'DejaVu Sans',Verdana,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;\
color:#222;line-height:1.45}h1{font-size:1.6em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:.3em .7em;text-align:right}\
th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}pre{background:#f6f6f6;padding:1em;\
overflow-x:auto;font-size:.85em}figure{margin:1.5em 0}figure img{display:block;position:relative;left:50%;\
transform:translateX(-50%);max-width:calc(100vw - 2em);border:1px solid #ddd}\
figcaption{font-size:.95em;color:#333;margin-top:.4em}.note{background:#fff6d8;border-left:4px solid #e0a800;\
padding:.6em 1em}.skipped{color:#666}";

/// Write the report for `input`, showing `drawn`, at `path` atomically.
pub(super) fn write(path: &Path, input: &FigureInput, drawn: &[Drawn]) -> Result<()> {
    let mut h = String::new();
    let w = &mut h;
    // Writing into a String cannot fail.
    let _ = write!(
        w,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>asperity study</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n<h1>asperity study: static friction from single- to \
         multi-asperity contact</h1>\n<p>The numerical study of Peng, Roch, Bonn &amp; Weber, Phys. Rev. Lett. \
         134, 176202 (2025): elastic contact of each topography at each load, then the stick-slip transition \
         model with each local friction law. {} topograph{}, {} friction law{}, {} result rows; computed by \
         asperity {} (commit {}).</p>\n",
        input.topographies.len(),
        if input.topographies.len() == 1 { "y" } else { "ies" },
        input.laws.len(),
        if input.laws.len() == 1 { "" } else { "s" },
        input.rows.len() + input.elastic_rows.len() + input.adhesive_rows.len(),
        crate::VERSION,
        escape(crate::COMMIT)
    );

    if let Some(limit) = &input.adhesion {
        let _ = writeln!(w, "<p class=\"adhesion\">{}</p>", escape(&super::coefficients::adhesion_sentence(limit)));
    }
    if let Some(found) = super::coefficients::adhesion_solved(input) {
        let sentence = format!("Every topography is also solved with adhesion, {found}.");
        let _ = writeln!(w, "<p class=\"adhesion-solved\">{}</p>", escape(&sentence));
    }

    // Plausibility first: a result a physicist knows is doubtful says so before any figure.
    let warnings = crate::study::warnings(input.rows);
    if !warnings.is_empty() {
        let _ = writeln!(w, "<h2 id=\"warnings\">Warnings</h2>\n<ul class=\"warnings\">");
        for warning in &warnings {
            let _ = writeln!(w, "<li>{}</li>", escape(warning));
        }
        let _ = writeln!(w, "</ul>");
    }

    // Contents: what was drawn and what was not.
    let _ = writeln!(w, "<h2>Figures</h2>\n<ul>");
    for d in drawn {
        let (title, paper) = heading(d.kind);
        if d.images.is_empty() {
            let _ = writeln!(w, "<li class=\"skipped\">{title} ({paper}): not drawn</li>");
        } else {
            let _ = writeln!(w, "<li><a href=\"#{}\">{title}</a> ({paper})</li>", stem(d.kind));
        }
    }
    let _ = writeln!(w, "</ul>");
    let notes: Vec<String> =
        drawn.iter().flat_map(|d| d.notes.iter().map(move |n| format!("{}: {}", heading(d.kind).0, n))).collect();
    if !notes.is_empty() {
        let _ = writeln!(w, "<p>Left out for lack of data:</p>\n<ul class=\"skipped\">");
        for n in notes {
            let _ = writeln!(w, "<li>{}</li>", escape(&n));
        }
        let _ = writeln!(w, "</ul>");
    }
    let requested: Vec<FigureKind> = drawn.iter().map(|d| d.kind).collect();
    let unrequested: Vec<&str> =
        FigureKind::ALL.iter().filter(|k| !requested.contains(k)).map(|k| heading(*k).0).collect();
    if !unrequested.is_empty() {
        let _ = writeln!(w, "<p class=\"skipped\">Not requested by the study: {}.</p>", unrequested.join(", "));
    }

    results(w, input);
    laws(w, input);
    limits(w);
    // A topography's own `grid` is its size before resampling; say what the solves ran on.
    let solved = match input.grid {
        Some((nx, ny)) => format!(
            "every topography resampled to the contact grid {nx} × {ny} (<code>[contact] grid</code>) and solved \
             there; a topography's own <code>grid</code> below is its size before resampling"
        ),
        None => "every topography solved on its own grid".to_string(),
    };
    let _ = writeln!(
        w,
        "<h2 id=\"parameters\">Parameters</h2>\n<p>The study as run (<code>study.toml</code>): {solved}.</p>\n\
         <pre>{}</pre>",
        escape(input.parameters)
    );

    for d in drawn.iter().filter(|d| !d.images.is_empty()) {
        let (title, paper) = heading(d.kind);
        let _ = writeln!(w, "<h2 id=\"{}\">{title} <small>({paper})</small></h2>", stem(d.kind));
        for image in &d.images {
            let file = escape(&image.file);
            let links = match &image.svg {
                Some(svg) => format!(" <a href=\"{file}\">PNG</a> · <a href=\"{}\">SVG</a>", escape(svg)),
                None => format!(" <a href=\"{file}\">GIF</a>"),
            };
            let _ = writeln!(
                w,
                "<figure>\n<a href=\"{file}\"><img src=\"{file}\" alt=\"{}\" loading=\"lazy\"></a>\n<figcaption>{}{links}</figcaption>\n</figure>",
                escape(title),
                escape(&image.caption)
            );
        }
    }
    let _ = writeln!(w, "</body>\n</html>");
    crate::output::write_atomic(path, |out| out.write_all(h.as_bytes()))
}

/// The friction drop per law at each load: its range over the topographies.
fn results(w: &mut String, input: &FigureInput) {
    let _ = writeln!(w, "<h2 id=\"results\">Results</h2>");
    // A column of the table: its heading and the rows per load.
    type Column<'a> = (String, Vec<(f64, Vec<&'a Row>)>);
    let mut columns: Vec<Column> =
        input.laws.iter().map(|l| (law_name(l), by_load(input.rows, &law_name(l)))).collect();
    for (rows, what) in [(input.weakening_rows, "equal sharing with d_c"), (input.elastic_rows, "elastic sharing")] {
        let more = input.laws.iter().map(|l| (format!("{}, {what}", law_name(l)), by_load(rows, &law_name(l))));
        columns.extend(more.filter(|c| !c.1.is_empty()).collect::<Vec<_>>());
    }
    let mut loads: Vec<f64> = columns.iter().flat_map(|c| c.1.iter().map(|g| g.0)).collect();
    loads.sort_by(f64::total_cmp);
    loads.dedup_by(|a, b| (*a / *b - 1.0).abs() < 1e-9);
    if loads.is_empty() {
        let _ = writeln!(w, "<p class=\"skipped\">No result rows.</p>");
        return;
    }
    let _ = writeln!(
        w,
        "<p>Friction drop F<sub>S</sub>/(μ<sup>D</sup> N) per law and normal load (equal sharing, and elastic \
         sharing where the study asks for it): the lowest and highest value over the {} topograph{}, and the \
         contact elements likewise. The full table is in <code>results.csv</code>.</p>\n<table>\n<tr><th>normal \
         load</th><th>contact elements</th>",
        input.topographies.len(),
        if input.topographies.len() == 1 { "y" } else { "ies" }
    );
    for (name, _) in &columns {
        let _ = write!(w, "<th>{}</th>", escape(name));
    }
    let _ = writeln!(w, "</tr>");
    for load in loads {
        let at = |groups: &[(f64, Vec<&Row>)]| groups.iter().position(|g| (g.0 / load - 1.0).abs() < 1e-9);
        let points = columns.iter().find_map(|c| at(&c.1).map(|k| &c.1[k].1)).map_or(String::from("–"), |rows| {
            let (lo, _, hi) = spread(rows.iter().map(|r| r.contact_points as f64));
            if lo == hi {
                format!("{lo:.0}")
            } else {
                format!("{lo:.0}–{hi:.0}")
            }
        });
        let _ = write!(w, "<tr><td>{}</td><td>{points}</td>", show(load, &FORCE));
        for (_, groups) in &columns {
            match at(groups).map(|k| &groups[k].1) {
                Some(rows) => {
                    let (lo, _, hi) = spread(rows.iter().map(|r| r.friction_drop));
                    if format!("{lo:.4}") == format!("{hi:.4}") {
                        let _ = write!(w, "<td>{lo:.4}</td>");
                    } else {
                        let _ = write!(w, "<td>{lo:.4}–{hi:.4}</td>");
                    }
                }
                None => {
                    let _ = write!(w, "<td>–</td>");
                }
            }
        }
        let _ = writeln!(w, "</tr>");
    }
    let _ = writeln!(w, "</table>");
    apart(w, input);
    slip_distance_band(w, input);
}

/// What the elastic interaction and the slip weakening each do: per law and load, the mean
/// drop over the topographies under equal sharing with the weakening, less the paper's (the
/// weakening alone), and under elastic sharing, less equal sharing's with the same weakening
/// (the interaction alone).
fn apart(w: &mut String, input: &FigureInput) {
    if input.weakening_rows.is_empty() || input.elastic_rows.is_empty() {
        return;
    }
    let mean = |rows: &[Row], law: &str, load: f64| {
        let groups = by_load(rows, law);
        let rows = &groups.iter().find(|g| (g.0 / load - 1.0).abs() < 1e-9)?.1;
        Some(spread(rows.iter().map(|r| r.friction_drop)).1)
    };
    let laws: Vec<String> =
        input.laws.iter().map(law_name).filter(|l| !by_load(input.weakening_rows, l).is_empty()).collect();
    let mut loads: Vec<f64> = input.elastic_rows.iter().map(|r| r.load_n).collect();
    loads.sort_by(f64::total_cmp);
    loads.dedup_by(|a, b| (*a / *b - 1.0).abs() < 1e-9);
    let _ = writeln!(
        w,
        "<p>The slip weakening and the elastic interaction apart: the mean friction drop over the topographies \
         under equal sharing with the slip weakening d<sub>c</sub> = {} less the paper's equal sharing (the \
         weakening alone), and under elastic sharing less equal sharing with the same weakening (the interaction \
         alone).</p>\n<table>\n<tr><th>normal load</th>",
        show(input.slip_distance_m, &LENGTH)
    );
    for law in &laws {
        let _ = write!(w, "<th>{}: weakening</th><th>{}: interaction</th>", escape(law), escape(law));
    }
    let _ = writeln!(w, "</tr>");
    for load in loads {
        let _ = write!(w, "<tr><td>{}</td>", show(load, &FORCE));
        for law in &laws {
            let weak = mean(input.weakening_rows, law, load);
            let cells = [
                weak.zip(mean(input.rows, law, load)).map(|(a, b)| a - b),
                mean(input.elastic_rows, law, load).zip(weak).map(|(a, b)| a - b),
            ];
            for cell in cells {
                let _ = match cell {
                    Some(d) => write!(w, "<td>{}</td>", signed(d)),
                    None => write!(w, "<td>–</td>"),
                };
            }
        }
        let _ = writeln!(w, "</tr>");
    }
    let _ = writeln!(w, "</table>");
}

/// How the slip-weakening distance steers the weakening models: per law and load, the mean drop
/// over the topographies under elastic sharing and under equal sharing with the weakening, at
/// the band's low end, at d_c and at its high end.
fn slip_distance_band(w: &mut String, input: &FigureInput) {
    let [low, high] = input.slip_distance_band else { return };
    if input.band_rows.is_empty() {
        return;
    }
    let distances = [*low, input.slip_distance_m, *high];
    let of = |sharing: Sharing, d: f64| -> Vec<Row> {
        let rows = input.weakening_rows.iter().chain(input.elastic_rows).chain(input.band_rows);
        rows.filter(|r| r.sharing == sharing && r.slip_distance_m == Some(d)).cloned().collect()
    };
    let models: Vec<Vec<Row>> =
        [Sharing::Elastic, Sharing::Equal].iter().flat_map(|&sharing| distances.map(|d| of(sharing, d))).collect();
    let dc = distances.map(|d| show(d, &LENGTH));
    let _ = writeln!(
        w,
        "<p>The slip-weakening distance d<sub>c</sub>, which the paper's model does not have: the mean friction \
         drop over the topographies under elastic sharing and under equal sharing with the same weakening, at \
         d<sub>c</sub> = {}, {} (the study's) and {}.</p>\n<table>\n<tr><th>law</th><th>normal load</th>",
        dc[0], dc[1], dc[2]
    );
    for what in ["elastic", "equal, weakening"] {
        for d in &dc {
            let _ = write!(w, "<th>{what}, d<sub>c</sub> {d}</th>");
        }
    }
    let _ = writeln!(w, "</tr>");
    for law in input.laws.iter().map(law_name) {
        let columns: Vec<Vec<(f64, Vec<&Row>)>> = models.iter().map(|rows| by_load(rows, &law)).collect();
        // The laws that follow a measured curve have no rows at the band's ends.
        let Some(loads) = columns.iter().find(|c| !c.is_empty()).filter(|_| columns.iter().all(|c| !c.is_empty()))
        else {
            continue;
        };
        for (load, _) in loads {
            let _ = write!(w, "<tr><td>{}</td><td>{}</td>", escape(&law), show(*load, &FORCE));
            for groups in &columns {
                let _ = match groups.iter().find(|g| (g.0 / load - 1.0).abs() < 1e-9) {
                    Some((_, rows)) => write!(w, "<td>{:.4}</td>", spread(rows.iter().map(|r| r.friction_drop)).1),
                    None => write!(w, "<td>–</td>"),
                };
            }
            let _ = writeln!(w, "</tr>");
        }
    }
    let _ = writeln!(w, "</table>");
}

/// The model's assumptions, as the paper states them.
fn limits(w: &mut String) {
    let _ = writeln!(
        w,
        "<h2 id=\"limits\">Limits of the model</h2>\n<ul>\n\
         <li>No elastic interaction between contact points: the tangential force is shared equally by the \
         stuck elements (a fibre bundle with equal load sharing), as the paper argues for patches far apart \
         beside their deformation; it may fail at high loads where patches come close. A study listing \
         <code>sharing = [\"elastic\"]</code> under <code>[model]</code> lifts this: the tangential force is then \
         shared through the elastic half-space (the body displaced rigidly along x), each element's coefficient \
         falling from μ<sub>s</sub> to μ<sub>d</sub> over the slip-weakening distance <code>slip_distance</code> \
         (2 nm by default: with an instant drop the onset has no length of its own and moves with the pixel). It \
         changes only how the tangential force is shared: the normal pressure stays the elastic normal solution \
         (no normal–tangential coupling, exact for similar materials such as Si on Si), and it keeps the other \
         limits below (the same pressure maps and contact area, no partial slip inside an element).</li>\n\
         <li>No Mindlin tangential compliance: an element is stuck or slipping, with no partial slip inside a \
         patch.</li>\n\
         <li>The contact area and the normal pressure stay fixed during sliding.</li>\n\
         <li>Elastic contact: local pressures above the hardness are not capped unless the study sets one.</li>\n\
         <li>The pixel is the model's element: results depend on the pixel size (see the resolution figure); \
         a study on a coarser grid (<code>--quick</code>) gives other numbers.</li>\n</ul>"
    );
}

/// The friction laws, with the warning that presets are not measurements.
fn laws(w: &mut String, input: &FigureInput) {
    let _ = writeln!(
        w,
        "<h2 id=\"laws\">Friction laws</h2>\n<table>\n<tr><th>law</th><th>μ<sub>s</sub></th><th>μ<sub>d</sub></th>\
         <th>μ<sub>s</sub>/μ<sub>d</sub> (single element)</th><th>source</th></tr>"
    );
    for law in input.laws {
        let source = if is_preset(law) { "preset: illustrative placeholder" } else { "study configuration" };
        let _ = writeln!(
            w,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.4}</td><td>{source}</td></tr>",
            escape(&law_name(law)),
            law.mu_s,
            law.mu_d,
            law.drop()
        );
    }
    let _ = writeln!(w, "</table>");
    if input.laws.iter().any(is_preset) {
        let _ = writeln!(
            w,
            "<p class=\"note\"><strong>Note:</strong> the preset laws' (μ<sub>s</sub>, μ<sub>d</sub>) values are \
             illustrative placeholders, not measurements: the paper reads them from AFM friction curves (its Fig. \
             S5) but states no values. They keep only the paper's ordering (the longer hold has the larger drop). \
             For quantitative predictions give measured values in the study's configuration.</p>"
        );
    } else {
        let _ = writeln!(w, "<p>The laws' values come from the study's configuration.</p>");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("<a href=\"x\">&'</a>"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;");
    }
}
