//! Output helpers: matrices as JSON rows, fixed-precision aligned tables.

use std::io::Write;

use faer::MatRef;
use nalgebra::{Dim, Matrix, RawStorage};
use serde::Serialize;
use sinew::paper::fixed;

use crate::error::CliError;

/// A matrix as an array of rows.
pub type Rows = Vec<Vec<f64>>;

/// A faer matrix as rows.
pub fn faer_rows(m: MatRef<'_, f64>) -> Rows {
    (0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect()).collect()
}

/// A nalgebra matrix as rows.
pub fn na_rows<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(m: &Matrix<f64, R, C, S>) -> Rows {
    (0..m.nrows()).map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect()).collect()
}

/// A nalgebra vector (or any matrix, column-major) as a flat list.
pub fn na_vec<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(m: &Matrix<f64, R, C, S>) -> Vec<f64> {
    m.iter().copied().collect()
}

/// Print a JSON document on standard output (see [`json_text`] for the layout).
pub fn print_json<T: Serialize>(value: &T) -> Result<(), CliError> {
    let value = serde_json::to_value(value)
        .map_err(|e| CliError::model(format!("cannot write the JSON output: {e}")))?;
    emit(&format!("{}\n", json_text(&value)))
}

/// Write to standard output. A closed pipe (`sinew … | head`) ends the output quietly instead
/// of panicking as `print!` would.
pub fn emit(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(CliError::input(format!("cannot write to standard output: {e}")))
        }
        _ => Ok(()),
    }
}

/// JSON laid out for reading as well as parsing: objects one key per line, arrays of scalars
/// on one line, so a matrix (array of rows) shows one row per line. Numbers as serde_json
/// writes them (shortest text that reads back to the same `f64`); non-finite numbers are null.
pub fn json_text(value: &serde_json::Value) -> String {
    let mut out = String::new();
    write_json(value, 0, &mut out);
    out
}

fn is_scalar(v: &serde_json::Value) -> bool {
    !matches!(v, serde_json::Value::Array(_) | serde_json::Value::Object(_))
}

fn write_json(value: &serde_json::Value, indent: usize, out: &mut String) {
    use serde_json::Value;
    let pad = |n: usize| "  ".repeat(n);
    match value {
        Value::Object(map) if !map.is_empty() => {
            out.push_str("{\n");
            for (k, (key, v)) in map.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                out.push_str(&Value::String(key.clone()).to_string());
                out.push_str(": ");
                write_json(v, indent + 1, out);
                out.push_str(if k + 1 < map.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push('}');
        }
        Value::Array(items) if !items.is_empty() && !items.iter().all(is_scalar) => {
            out.push_str("[\n");
            for (k, v) in items.iter().enumerate() {
                out.push_str(&pad(indent + 1));
                write_json(v, indent + 1, out);
                out.push_str(if k + 1 < items.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push(']');
        }
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(Value::to_string).collect();
            out.push('[');
            out.push_str(&items.join(", "));
            out.push(']');
        }
        scalar => out.push_str(&scalar.to_string()),
    }
}

/// How to print a number.
#[derive(Debug, Clone, Copy)]
pub enum Fmt {
    /// Fixed point, this many decimals.
    Fixed(usize),
    /// Scientific, this many decimals in the mantissa.
    Sci(usize),
}

impl Fmt {
    /// `x` in this format (`-0` printed as `0`).
    pub fn num(self, x: f64) -> String {
        match self {
            Fmt::Fixed(d) => fixed(x, d),
            Fmt::Sci(d) => {
                // `1.2345e-4` as `1.2345e-04`, `-0` as `0`.
                let x = if x == 0.0 { 0.0 } else { x };
                let s = format!("{x:.d$e}");
                match s.split_once('e').map(|(m, e)| (m, e.parse::<i32>())) {
                    Some((m, Ok(e))) => {
                        format!("{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
                    }
                    _ => s,
                }
            }
        }
    }

    /// A list, `[a, b, c]`.
    pub fn list(self, xs: &[f64]) -> String {
        let items: Vec<String> = xs.iter().map(|&x| self.num(x)).collect();
        format!("[{}]", items.join(", "))
    }
}

/// A table: a header row and rows of cells; the first column (and any marked with
/// [`Table::left`]) is left-aligned, the others right-aligned, every column as wide as its widest cell.
#[derive(Debug, Default)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    left: Vec<usize>,
}

impl Table {
    /// A table with this header (empty strings for no header).
    pub fn new<S: AsRef<str>>(header: &[S]) -> Table {
        Table {
            header: header.iter().map(|s| s.as_ref().to_owned()).collect(),
            rows: Vec::new(),
            left: vec![0],
        }
    }

    /// Left-align these columns too (text columns; the first always is).
    pub fn left(mut self, columns: &[usize]) -> Table {
        self.left.extend_from_slice(columns);
        self
    }

    /// Add a row.
    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }

    /// The table as text, each line indented by `indent` spaces.
    pub fn render(&self, indent: usize) -> String {
        let columns = self.rows.iter().map(Vec::len).chain([self.header.len()]).max().unwrap_or(0);
        let mut widths = vec![0; columns];
        for row in self.rows.iter().chain([&self.header]) {
            for (w, cell) in widths.iter_mut().zip(row) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let pad = " ".repeat(indent);
        let mut out = String::new();
        let has_header = self.header.iter().any(|h| !h.is_empty());
        let lines = has_header.then_some(&self.header).into_iter().chain(self.rows.iter());
        for row in lines {
            let mut line = pad.clone();
            for (k, w) in widths.iter().enumerate() {
                let cell = row.get(k).map(String::as_str).unwrap_or("");
                let fill = " ".repeat(w - cell.chars().count());
                if k > 0 {
                    line.push_str("  ");
                }
                if self.left.contains(&k) {
                    line.push_str(cell);
                    line.push_str(&fill);
                } else {
                    line.push_str(&fill);
                    line.push_str(cell);
                }
            }
            out.push_str(line.trim_end());
            out.push('\n');
        }
        out
    }
}

/// A titled matrix, rows labelled `row_labels` (or 1, 2, … when empty), columns likewise.
pub fn matrix(
    title: &str,
    rows: &Rows,
    fmt: Fmt,
    row_labels: &[String],
    col_labels: &[String],
) -> String {
    let ncols = rows.first().map_or(0, Vec::len);
    let label =
        |labels: &[String], k: usize| labels.get(k).cloned().unwrap_or(format!("{}", k + 1));
    let mut header = vec![String::new()];
    header.extend((0..ncols).map(|j| label(col_labels, j)));
    let mut table = Table::new(&header);
    for (i, row) in rows.iter().enumerate() {
        let mut cells = vec![label(row_labels, i)];
        cells.extend(row.iter().map(|&x| fmt.num(x)));
        table.row(cells);
    }
    format!("{title}\n{}", table.render(2))
}

/// Labels of a wrench or twist: linear rows first.
pub fn cartesian_labels() -> Vec<String> {
    ["x", "y", "z", "rx", "ry", "rz"].iter().map(|s| (*s).to_owned()).collect()
}

/// Labels of the revolute joints (`q11`, `q12`, `q21`, …: joint number from 1, then axis).
pub fn q_labels(groups: &[std::ops::Range<usize>]) -> Vec<String> {
    groups
        .iter()
        .enumerate()
        .flat_map(|(j, g)| {
            let single = g.len() == 1;
            (0..g.len()).map(move |k| {
                if single { format!("q{}", j + 1) } else { format!("q{}{}", j + 1, k + 1) }
            })
        })
        .collect()
}
