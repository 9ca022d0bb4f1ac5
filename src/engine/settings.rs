//! What a stage's settings table returns when a value is out of its range: the key within the
//! table and one line saying why. Each stage defines its table beside its code (serde,
//! `Default`, unknown keys refused) and its own `validate`; the set-up layer adds the table's
//! path (`scheme.ppe.tolerance`) and keeps only the checks that span several tables.

/// A key of a stage's table and what is wrong with its value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Invalid {
    /// The key within the stage's table (`tolerance`, not `scheme.ppe.tolerance`).
    pub key: &'static str,
    pub message: String,
}

impl Invalid {
    pub fn new(key: &'static str, message: impl Into<String>) -> Self {
        Self {
            key,
            message: message.into(),
        }
    }
}

/// `v` if it lies in [lo, hi], else the error naming `key`.
pub fn in_range(key: &'static str, v: f64, lo: f64, hi: f64) -> Result<f64, Invalid> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(Invalid::new(
            key,
            format!("must be in [{lo}, {hi}], got {v}"),
        ))
    }
}

/// `v` if it is a positive number, else the error naming `key`.
pub fn positive(key: &'static str, v: f64) -> Result<f64, Invalid> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Invalid::new(
            key,
            format!("must be a positive number, got {v}"),
        ))
    }
}
