//! `--set key=value` overrides of any dotted key of a case file, applied to the parsed table
//! before it is read.

/// Sets a dotted key, e.g. `fluid.beta=0.2`. The value is read as TOML (number, boolean,
/// array, quoted string) and otherwise taken as a bare string (`scheme.frame=eulerian`).
pub fn apply_override(table: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (key, value) = assignment.split_once('=').ok_or("expected key=value")?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|k| k.trim().is_empty()) {
        return Err("empty key".into());
    }
    let value = value.trim();
    if value.is_empty() {
        return Err("empty value".into());
    }
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    let parts: Vec<&str> = key.split('.').map(str::trim).collect();
    let mut current = table;
    for part in &parts[..parts.len() - 1] {
        let entry = current
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        current = entry
            .as_table_mut()
            .ok_or_else(|| format!("`{part}` is not a table"))?;
    }
    current.insert(parts[parts.len() - 1].to_string(), parsed);
    Ok(())
}
