//! A dataset's manifest as Parquet (`manifest.parquet`), beside the CSV and with its rows: what
//! pandas, Polars, DuckDB, PyArrow and Hugging Face `datasets` read with their types. `sample`
//! is an INT64; a draw whose every value is a number (`inf` too) is a DOUBLE, else UTF-8 text; the
//! metrics are nullable DOUBLEs (null where metrics.json has none); the paths nullable UTF-8.
//! One row group, no compression, no timestamps: the same bytes for the same manifest.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};
use parquet::data_type::ByteArray;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::parser::parse_message_type;

use crate::io::atomic::write_atomically;
use crate::measure::dataset::{FILE_COLUMNS, METRIC_COLUMNS, Manifest};

/// The file's name in the dataset folder.
pub const MANIFEST_PARQUET: &str = "manifest.parquet";

/// One column's values, typed.
enum Column {
    Int(Vec<i64>),
    /// Values with `None` as null.
    Double(Vec<Option<f64>>),
    Text(Vec<Option<String>>),
}

impl Column {
    fn schema_line(&self, name: &str) -> String {
        match self {
            Column::Int(_) => format!("REQUIRED INT64 {name};"),
            Column::Double(_) => format!("OPTIONAL DOUBLE {name};"),
            Column::Text(_) => format!("OPTIONAL BYTE_ARRAY {name} (UTF8);"),
        }
    }
}

/// The manifest's columns, in its header's order.
fn columns(manifest: &Manifest) -> Vec<(String, Column)> {
    let mut out = vec![(
        "sample".to_string(),
        Column::Int(manifest.rows.iter().map(|r| r.sample as i64).collect()),
    )];
    for (k, name) in manifest.draws.iter().enumerate() {
        let texts: Vec<&str> = manifest.rows.iter().map(|r| r.draws[k].as_str()).collect();
        let numbers: Option<Vec<Option<f64>>> = texts
            .iter()
            .map(|t| t.trim().parse::<f64>().ok().map(Some))
            .collect();
        let column = match numbers {
            Some(n) => Column::Double(n),
            None => Column::Text(texts.iter().map(|t| Some(t.to_string())).collect()),
        };
        out.push((name.clone(), column));
    }
    for (k, (name, _, _)) in METRIC_COLUMNS.iter().enumerate() {
        let values = manifest.rows.iter().map(|r| r.metrics[k]).collect();
        out.push((name.to_string(), Column::Double(values)));
    }
    for (k, (name, _)) in FILE_COLUMNS.iter().enumerate() {
        let values = manifest.rows.iter().map(|r| r.files[k].clone()).collect();
        out.push((name.to_string(), Column::Text(values)));
    }
    out
}

/// Definition levels (1 present, 0 null) and the present values.
fn levels<T: Clone>(values: &[Option<T>]) -> (Vec<i16>, Vec<T>) {
    let defs = values.iter().map(|v| v.is_some() as i16).collect();
    let present = values.iter().flatten().cloned().collect();
    (defs, present)
}

/// The Parquet file's bytes.
pub fn manifest_parquet(manifest: &Manifest) -> Result<Vec<u8>> {
    let columns = columns(manifest);
    let schema: String = columns
        .iter()
        .map(|(name, column)| column.schema_line(name))
        .collect::<Vec<_>>()
        .join(" ");
    let schema = Arc::new(parse_message_type(&format!(
        "message manifest {{ {schema} }}"
    ))?);
    let properties = Arc::new(
        WriterProperties::builder()
            .set_created_by("seethru".to_string())
            .build(),
    );
    let mut bytes = Vec::new();
    let mut writer = SerializedFileWriter::new(&mut bytes, schema, properties)?;
    let mut group = writer.next_row_group()?;
    for (_, column) in &columns {
        let mut out = group.next_column()?.context("a column per schema field")?;
        use parquet::column::writer::ColumnWriter as W;
        match (out.untyped(), column) {
            (W::Int64ColumnWriter(w), Column::Int(v)) => {
                w.write_batch(v, None, None)?;
            }
            (W::DoubleColumnWriter(w), Column::Double(v)) => {
                let (defs, present) = levels(v);
                w.write_batch(&present, Some(&defs), None)?;
            }
            (W::ByteArrayColumnWriter(w), Column::Text(v)) => {
                let (defs, present) = levels(v);
                let present: Vec<ByteArray> = present
                    .into_iter()
                    .map(|s: String| ByteArray::from(s.into_bytes()))
                    .collect();
                w.write_batch(&present, Some(&defs), None)?;
            }
            _ => unreachable!("each column's writer is of its schema line's type"),
        }
        out.close()?;
    }
    group.close()?;
    writer.close()?;
    Ok(bytes)
}

/// Writes `manifest.parquet` (whole or not at all).
pub fn write_manifest_parquet(path: &Path, manifest: &Manifest) -> Result<()> {
    let bytes = manifest_parquet(manifest)?;
    write_atomically(path, |file| {
        std::io::Write::write_all(file, &bytes)?;
        Ok(())
    })
}
