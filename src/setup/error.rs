//! The one kind of error a case file gets: one line naming the file and the dotted field.

use std::fmt;

/// A bad case file or override: one line naming the file and the field.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseError {
    pub file: String,
    pub field: String,
    pub message: String,
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}", self.file, self.message)
        } else {
            write!(f, "{}: field `{}`: {}", self.file, self.field, self.message)
        }
    }
}

impl std::error::Error for CaseError {}

/// A field and what is wrong with it (the file is added by the caller).
pub type FieldError = (String, String);

pub fn field_err(field: &str, message: impl Into<String>) -> FieldError {
    (field.to_string(), message.into())
}

/// A stage's own check ([`crate::engine::settings::Invalid`]), its key under `table`.
pub fn stage_err(table: &str, e: crate::engine::settings::Invalid) -> FieldError {
    field_err(&format!("{table}.{}", e.key), e.message)
}

pub fn positive(field: &str, v: f64) -> Result<f64, FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(field_err(
            field,
            format!("must be a positive number, got {v}"),
        ))
    }
}

pub fn in_range(field: &str, v: f64, lo: f64, hi: f64) -> Result<f64, FieldError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(field_err(
            field,
            format!("must be in [{lo}, {hi}], got {v}"),
        ))
    }
}

/// Deserializes a table with `serde_path_to_error`, naming fields `<prefix>.<path>` (and an
/// unknown key by its own name rather than the table's).
pub fn read_table<T: for<'de> serde::Deserialize<'de>>(
    value: toml::Value,
    prefix: &str,
) -> Result<T, FieldError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let message = e.into_inner().message().trim().replace('\n', "; ");
        let join = |key: &str| match (prefix.is_empty(), key == ".") {
            (true, true) => String::new(),
            (true, false) => key.to_string(),
            (false, true) => prefix.to_string(),
            (false, false) => format!("{prefix}.{key}"),
        };
        let field = match message.strip_prefix("unknown field `") {
            Some(rest) => {
                let key = rest.split('`').next().unwrap_or_default();
                match path.as_str() {
                    "." => join(key),
                    p if p == key || p.ends_with(&format!(".{key}")) => join(p),
                    p => join(&format!("{p}.{key}")),
                }
            }
            None => join(&path),
        };
        field_err(&field, message)
    })
}
