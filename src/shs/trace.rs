//! Slide-hold-slide traces: time series of friction force, normal force and, if the instrument
//! records it, sliding displacement, as exported to CSV.
//!
//! Must not import topography, contact, friction, study, plot or report: a trace is its own input.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Names and units of the columns of a trace file. The defaults read
/// `time_s,friction_n,normal_n[,displacement_m]` in seconds, newtons and metres.
#[derive(Clone, Debug)]
pub struct TraceFormat {
    /// Header of the time column (default `time_s`).
    pub time_column: String,
    /// Header of the friction (shear) force column (default `friction_n`).
    pub friction_column: String,
    /// Header of the normal force column (default `normal_n`).
    pub normal_column: String,
    /// `None`: use a column `displacement_m` if the file has one, else derive displacement from
    /// time and the sliding speed. `Some(name)`: the file must have that column.
    pub displacement_column: Option<String>,
    /// Seconds per unit of the time column.
    pub time_unit: f64,
    /// Newtons per unit of the friction column.
    pub friction_unit: f64,
    /// Newtons per unit of the normal force column.
    pub normal_unit: f64,
    /// Metres per unit of the displacement column.
    pub displacement_unit: f64,
}

impl Default for TraceFormat {
    fn default() -> Self {
        TraceFormat {
            time_column: "time_s".into(),
            friction_column: "friction_n".into(),
            normal_column: "normal_n".into(),
            displacement_column: None,
            time_unit: 1.0,
            friction_unit: 1.0,
            normal_unit: 1.0,
            displacement_unit: 1.0,
        }
    }
}

/// The default name of the optional displacement column.
pub const DISPLACEMENT_COLUMN: &str = "displacement_m";

/// A slide-hold-slide trace in SI units: time \[s] strictly increasing, friction and normal
/// force \[N], and displacement \[m] when the instrument recorded it.
#[derive(Clone, Debug)]
pub struct Trace {
    source: PathBuf,
    time: Vec<f64>,
    friction: Vec<f64>,
    normal: Vec<f64>,
    displacement: Option<Vec<f64>>,
}

impl Trace {
    /// A trace from columns of equal length; `source` names it in errors. Values must be
    /// finite and time strictly increasing.
    pub fn new(
        source: impl Into<PathBuf>,
        time: Vec<f64>,
        friction: Vec<f64>,
        normal: Vec<f64>,
        displacement: Option<Vec<f64>>,
    ) -> Result<Trace> {
        let source = source.into();
        let n = time.len();
        if friction.len() != n || normal.len() != n || displacement.as_ref().is_some_and(|x| x.len() != n) {
            return Err(Error::file(&source, "columns of different lengths"));
        }
        if n < 2 {
            return Err(Error::file(&source, format!("{n} samples: a trace needs at least two")));
        }
        let columns = [("time", Some(&time)), ("friction", Some(&friction)), ("normal force", Some(&normal))];
        for (name, column) in columns.into_iter().chain([("displacement", displacement.as_ref())]) {
            if let Some(i) = column.and_then(|c| c.iter().position(|v| !v.is_finite())) {
                return Err(Error::file(&source, format!("sample {}: {name} is not a finite number", i + 1)));
            }
        }
        if let Some(i) = time.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::file(
                &source,
                format!("sample {}: time {} s does not increase (previous {} s)", i + 2, time[i + 1], time[i]),
            ));
        }
        Ok(Trace { source, time, friction, normal, displacement })
    }

    /// Where the trace came from.
    pub fn source(&self) -> &Path {
        &self.source
    }
    /// Time \[s].
    pub fn time(&self) -> &[f64] {
        &self.time
    }
    /// Friction force \[N].
    pub fn friction(&self) -> &[f64] {
        &self.friction
    }
    /// Normal force \[N].
    pub fn normal(&self) -> &[f64] {
        &self.normal
    }
    /// Measured sliding displacement \[m], if the file had it.
    pub fn displacement(&self) -> Option<&[f64]> {
        self.displacement.as_deref()
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }
    /// Whether the trace has no sample.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }
}

/// The delimiter of a CSV file's header row (its first line that is not a comment): the most
/// frequent of comma, semicolon and tab in it, a comma when it has none (spreadsheets in many
/// locales export semicolons).
fn delimiter(bytes: &[u8]) -> u8 {
    let header = bytes.split(|&b| b == b'\n').find(|line| !line.trim_ascii().is_empty() && !line.starts_with(b"#"));
    let header = header.unwrap_or_default();
    let count = |d: u8| header.iter().filter(|&&b| b == d).count();
    [b',', b';', b'\t'].into_iter().max_by_key(|&d| (count(d), d == b',')).unwrap_or(b',')
}

/// Read a trace from a CSV file with a header row, its values separated by commas, semicolons
/// or tabs (as its header is). Lines starting with `#` are comments;
/// columns other than the four named in `format` are ignored. Errors name the file and, for a
/// bad value, its line and column.
pub fn read_trace(path: &Path, format: &TraceFormat) -> Result<Trace> {
    let bytes = crate::limits::Limits::default().read_file(path)?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .delimiter(delimiter(&bytes))
        .from_reader(&bytes[..]);
    let headers = reader.headers().map_err(|e| csv_error(path, e))?.clone();
    if headers.iter().all(str::is_empty) {
        return Err(Error::file(path, "empty file: no header row"));
    }
    let find = |name: &str| headers.iter().position(|h| h == name);
    let require = |name: &str| {
        find(name).ok_or_else(|| {
            let found: Vec<&str> = headers.iter().collect();
            Error::file(path, format!("no column '{name}' (columns: {})", found.join(", ")))
        })
    };
    let mut columns = vec![
        (format.time_column.as_str(), require(&format.time_column)?, format.time_unit),
        (format.friction_column.as_str(), require(&format.friction_column)?, format.friction_unit),
        (format.normal_column.as_str(), require(&format.normal_column)?, format.normal_unit),
    ];
    let displacement = match &format.displacement_column {
        Some(name) => Some((name.as_str(), require(name)?)),
        None => find(DISPLACEMENT_COLUMN).map(|i| (DISPLACEMENT_COLUMN, i)),
    };
    if let Some((name, i)) = displacement {
        columns.push((name, i, format.displacement_unit));
    }

    let mut values: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut record = csv::StringRecord::new();
    let mut previous_time: Option<f64> = None;
    loop {
        match reader.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_error(path, e)),
        }
        let line = record.position().map_or(0, |p| p.line());
        for ((name, index, unit), column) in columns.iter().zip(values.iter_mut()) {
            let text = &record[*index];
            let v: f64 = text
                .parse()
                .map_err(|_| Error::file(path, format!("line {line}, column '{name}': '{text}' is not a number")))?;
            if !v.is_finite() {
                return Err(Error::file(path, format!("line {line}, column '{name}': '{text}' is not finite")));
            }
            column.push(v * unit);
        }
        let t = values[0][values[0].len() - 1];
        if let Some(p) = previous_time.filter(|&p| t <= p) {
            return Err(Error::file(
                path,
                format!("line {line}: time {t} s does not increase (previous {p} s); time must be strictly monotonic"),
            ));
        }
        previous_time = Some(t);
    }
    let displacement = if displacement.is_some() { values.pop() } else { None };
    let mut it = values.into_iter();
    let (time, friction, normal) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
    Trace::new(path, time, friction, normal, displacement)
}

fn csv_error(path: &Path, e: csv::Error) -> Error {
    let line = e.position().map_or(0, |p| p.line());
    match e.kind() {
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
            Error::file(path, format!("line {line}: {len} fields where the header has {expected_len}"))
        }
        csv::ErrorKind::Utf8 { .. } => Error::file(path, format!("line {line}: not valid UTF-8")),
        csv::ErrorKind::Io(_) => match e.into_kind() {
            csv::ErrorKind::Io(io) => Error::io(path, io),
            _ => unreachable!("matched an I/O error above"),
        },
        _ => Error::file(path, format!("malformed CSV: {e}")),
    }
}
