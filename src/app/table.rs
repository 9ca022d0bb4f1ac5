//! CSV tables: every CSV file the program writes has one row type, a
//! `#[derive(Serialize, Deserialize)]` struct whose field names are the header, written and
//! read back through the `csv` crate here. The header is the struct, so a column cannot be
//! added to the rows and forgotten in the header (or read back from the wrong position), and a
//! bad value read back is reported with its file, row and column.
//!
//! Numbers keep the formatting each column has always had (`{:.8e}` for times, `{:.6e}` for
//! most quantities, ...): the `serialize_with` functions of [`fmt`] write the formatted text,
//! so the files' bytes, which the regression fingerprints hash, do not depend on the `csv`
//! crate's own float formatting.

use anyhow::{Context, Result};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::Path;

/// The rows as CSV text, the header from `T`'s field names. An empty table still has its
/// header (from `T::default()`, whose values are dropped): readers and charts expect one.
pub fn write_rows<T: Serialize + Default>(rows: &[T]) -> String {
    write_with(rows, csv::QuoteStyle::Necessary)
}

/// Like [`write_rows`], but no field is quoted by the writer: for a table whose row type quotes
/// a column itself ([`fmt::quoted`]), as `stability.csv` has always quoted its `reason`, so
/// that the file keeps its bytes. Only for rows whose other fields hold no comma or quote.
pub fn write_rows_verbatim<T: Serialize + Default>(rows: &[T]) -> String {
    write_with(rows, csv::QuoteStyle::Never)
}

fn write_with<T: Serialize + Default>(rows: &[T], quoting: csv::QuoteStyle) -> String {
    let mut w = csv::WriterBuilder::new()
        .quote_style(quoting)
        .from_writer(Vec::with_capacity(64 + 128 * rows.len()));
    // The row types are plain structs of numbers and strings, which the writer always takes:
    // an error here is a row type the writer cannot flatten, a bug every table's test catches.
    let bug = "a CSV row type the csv writer cannot write";
    if rows.is_empty() {
        w.serialize(T::default()).expect(bug);
    }
    for row in rows {
        w.serialize(row).expect(bug);
    }
    let bytes = w.into_inner().expect(bug);
    let mut text = String::from_utf8(bytes).expect("CSV of UTF-8 strings");
    if rows.is_empty() {
        let header = text.find('\n').map_or(text.len(), |n| n + 1);
        text.truncate(header);
    }
    text
}

/// Reads the rows of the CSV file at `path` by column name (extra columns are ignored, a
/// missing one is an error unless its field has a default).
pub fn read_rows<T: DeserializeOwned>(path: &Path) -> Result<Vec<T>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    parse_rows(&text, &path.display().to_string())
}

/// The rows of CSV `text` (read from `source`, which errors name).
pub fn parse_rows<T: DeserializeOwned>(text: &str, source: &str) -> Result<Vec<T>> {
    parse_with(&csv::ReaderBuilder::new(), text, source)
}

/// Like [`read_rows`], for a table written by hand (published values): lines starting with
/// `#` are comments, fields are trimmed and rows may have more columns than the header.
pub fn read_rows_commented<T: DeserializeOwned>(path: &Path) -> Result<Vec<T>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut builder = csv::ReaderBuilder::new();
    builder
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true);
    parse_with(&builder, &text, &path.display().to_string())
}

fn parse_with<T: DeserializeOwned>(
    builder: &csv::ReaderBuilder,
    text: &str,
    source: &str,
) -> Result<Vec<T>> {
    let mut reader = builder.from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .with_context(|| format!("reading {source}: header"))?
        .clone();
    reader
        .deserialize()
        .map(|row| row.map_err(|e| row_error(source, &headers, e)))
        .collect()
}

/// `reading plots/x/series.csv: row 12 (line 13), column "drag_k": invalid float literal`.
fn row_error(source: &str, headers: &csv::StringRecord, e: csv::Error) -> anyhow::Error {
    let place = |pos: Option<&csv::Position>| {
        pos.map_or(String::new(), |p| {
            format!(" row {} (line {}),", p.record(), p.line())
        })
    };
    match e.kind() {
        csv::ErrorKind::Deserialize { pos, err } => {
            let column = err
                .field()
                .and_then(|k| headers.get(k as usize))
                .map_or(String::new(), |name| format!(" column {name:?}:"));
            anyhow::anyhow!(
                "reading {source}:{}{column} {}",
                place(pos.as_ref()),
                err.kind()
            )
        }
        _ => anyhow::Error::new(e).context(format!("reading {source}")),
    }
}

/// NaN: the value of a column that a file written before the column existed lacks
/// (`#[serde(default = "table::nan")]`), where NaN already means "not measured".
pub fn nan() -> f64 {
    f64::NAN
}

/// `serialize_with` functions: each writes a number as the text of one format, the column's
/// since before the tables went through `csv`.
pub mod fmt {
    use serde::Serializer;

    macro_rules! formats {
        ($($(#[$doc:meta])* $name:ident $opt:ident => $f:literal;)*) => {$(
            $(#[$doc])*
            pub fn $name<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(&format_args!($f, v))
            }
            /// As the plain format, an empty field for `None`.
            pub fn $opt<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
                match v {
                    Some(v) => $name(v, s),
                    None => s.serialize_str(""),
                }
            }
        )*};
    }

    formats! {
        /// `{:.3e}`.
        sci3 opt_sci3 => "{:.3e}";
        /// `{:.4e}`.
        sci4 opt_sci4 => "{:.4e}";
        /// `{:.6e}`.
        sci6 opt_sci6 => "{:.6e}";
        /// `{:.8e}`.
        sci8 opt_sci8 => "{:.8e}";
        /// `{:.9e}`.
        sci9 opt_sci9 => "{:.9e}";
        /// `{:.0}`.
        fixed0 opt_fixed0 => "{:.0}";
        /// `{:.1}`.
        fixed1 opt_fixed1 => "{:.1}";
        /// `{:.2}`.
        fixed2 opt_fixed2 => "{:.2}";
        /// `{:.3}`.
        fixed3 opt_fixed3 => "{:.3}";
        /// `{:.4}`.
        fixed4 opt_fixed4 => "{:.4}";
        /// `{}`: the shortest text that reads back to the same number, without an exponent
        /// (the csv writer's own would write `1.0` and `1e-7` where this writes `1` and
        /// `0.0000001`).
        plain opt_plain => "{}";
    }

    /// A string always in double quotes (empty ones and `None` too), its own double quotes
    /// turned into single ones, for [`super::write_rows_verbatim`]; the reader takes the
    /// quotes off again.
    pub fn quoted<S: Serializer>(v: &Option<String>, s: S) -> Result<S::Ok, S::Error> {
        let v = v.as_deref().unwrap_or("");
        s.collect_str(&format_args!("\"{}\"", v.replace('"', "'")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::io::SeriesRow;
    use serde::Deserialize;

    /// A row with a formatted column, an optional one and a string.
    #[derive(Debug, Default, PartialEq, Serialize, Deserialize)]
    struct Row {
        #[serde(serialize_with = "fmt::sci6")]
        t: f64,
        #[serde(serialize_with = "fmt::opt_fixed3")]
        order: Option<f64>,
        label: String,
    }

    #[test]
    fn rows_are_written_in_their_formats_and_read_back() {
        let rows = [
            Row {
                t: 0.5,
                order: Some(2.0),
                label: "log".into(),
            },
            Row {
                t: f64::NAN,
                order: None,
                label: "a, b".into(),
            },
        ];
        let text = write_rows(&rows);
        assert_eq!(
            text,
            "t,order,label\n5.000000e-1,2.000,log\nNaN,,\"a, b\"\n"
        );
        let back: Vec<Row> = parse_rows(&text, "rows.csv").unwrap();
        assert_eq!(back[0], rows[0]);
        assert!(back[1].t.is_nan() && back[1].order.is_none());
        assert_eq!(back[1].label, "a, b");
    }

    /// Readers and charts expect the header of a table with no rows yet.
    #[test]
    fn an_empty_table_has_its_header() {
        assert_eq!(write_rows::<Row>(&[]), "t,order,label\n");
    }

    /// A bad value read back names the file, the row and the column.
    #[test]
    fn a_bad_value_names_file_row_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("series.csv");
        let marked = SeriesRow {
            drag_k: 1.5,
            ..Default::default()
        };
        let text = write_rows(&[SeriesRow::default(), marked]);
        assert_eq!(text.matches("1.500000e0").count(), 1);
        std::fs::write(&path, text.replace("1.500000e0", "1.5e0x")).unwrap();
        let e = read_rows::<SeriesRow>(&path).expect_err("a bad float must be refused");
        let e = format!("{e:#}");
        assert!(e.contains(&format!("reading {}:", path.display())), "{e}");
        assert!(e.contains("row 2 (line 3)"), "{e}");
        assert!(e.contains("column \"drag_k\""), "{e}");
        assert!(e.contains("invalid float literal"), "{e}");
    }
}
