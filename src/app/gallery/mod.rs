//! The validation gallery's tables, generated from the run outputs committed under `plots/`
//! (`plots/regenerate.sh` reruns the runs). A page marks each generated table:
//!
//! ```text
//! <!-- generated: convergence plots/couette/explicit/convergence.csv -->
//! | frame | H/δr | ... |
//! <!-- end generated -->
//! ```
//!
//! `rheosph gallery` rewrites every marked table from its source and lists each number that
//! changed; `rheosph gallery --check` writes nothing and fails on a committed number that its
//! source contradicts, so a page cannot quote a figure the runs no longer give, and on a
//! result typed in the prose around the tables ([`typed`]). Wall-clock columns are shown but
//! not compared: they belong to the machine and the day of the run.

use crate::app::study::{convergence, cylinder, speed_accuracy, stability};
use crate::app::table;
use anyhow::{bail, Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod typed;

const OPEN: &str = "<!-- generated:";
const CLOSE: &str = "<!-- end generated -->";
/// The header of every column that holds a wall-clock time (not compared by the check).
const WALL: &str = "wall s";

/// What a block tabulates, and from which file of a run or study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// `convergence.csv` of `rheosph study convergence`.
    Convergence,
    /// `stability.csv`: one row per variant, one column per Wi.
    Stability,
    /// `speed_accuracy.csv`.
    SpeedAccuracy,
    /// `cylinder.csv` of `rheosph study cylinder`.
    Cylinder,
    /// The `summary.json` of each start-up run directory named.
    Runs,
    /// The `summary.json` of each run to a steady state named.
    Steady,
    /// Chosen fields of each named run's `summary.json`: `name=/json/pointer` words name
    /// the columns (`_` in a name is a space; a pointer ending in `%` is a fraction shown as
    /// a percentage), the other words the run directories.
    Values,
    /// Chosen columns of a committed CSV file, row by row: `name=column` words (the file's
    /// header names the columns), the other word the file.
    Columns,
}

impl Kind {
    fn parse(word: &str) -> Option<Kind> {
        Some(match word {
            "convergence" => Kind::Convergence,
            "stability" => Kind::Stability,
            "speed-accuracy" => Kind::SpeedAccuracy,
            "cylinder" => Kind::Cylinder,
            "runs" => Kind::Runs,
            "steady" => Kind::Steady,
            "values" => Kind::Values,
            "columns" => Kind::Columns,
            _ => return None,
        })
    }
}

/// A Markdown table as cells of text.
#[derive(Clone, Debug, Default, PartialEq)]
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn new(header: &[&str]) -> Table {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    fn markdown(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let mut text = line(&self.header);
        text += &line(&vec!["---".to_string(); self.header.len()]);
        for row in &self.rows {
            text += &line(row);
        }
        text
    }

    /// The table of Markdown `lines` (the header, the rule, the rows).
    fn parse(lines: &[&str]) -> Table {
        let cells = |l: &str| -> Vec<String> {
            let l = l.trim().trim_start_matches('|').trim_end_matches('|');
            l.split('|').map(|c| c.trim().to_string()).collect()
        };
        let mut rows = lines.iter().filter(|l| l.trim_start().starts_with('|'));
        let header = rows.next().map(|l| cells(l)).unwrap_or_default();
        let rows = rows.skip(1).map(|l| cells(l)).collect();
        Table { header, rows }
    }
}

/// A committed number its source contradicts (or a table whose shape changed).
#[derive(Clone, Debug, PartialEq)]
pub struct Contradiction {
    /// `page:line` of the block's opening marker.
    pub place: String,
    /// The block's kind and source, as the marker names them.
    pub block: String,
    pub what: String,
}

impl std::fmt::Display for Contradiction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.place, self.block, self.what)
    }
}

/// A value to `digits` significant digits, without an exponent down to 0.001; `–` if not
/// finite.
fn sig(v: f64, digits: i32) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if magnitude < -3 {
        // Below 0.001 the digits would hide behind zeros: 1.19e-7, not 0.0000001192.
        let decimals = (digits - 1).max(0) as usize;
        return format!("{v:.decimals$e}");
    }
    let decimals = (digits - 1 - magnitude).max(0) as usize;
    format!("{v:.decimals$}")
}

/// A count or a time as short as it reads: `5`, `4.35`, `2663` (four significant digits,
/// trailing zeros dropped).
fn short(v: f64) -> String {
    let s = sig(v, 4);
    match s.contains('.') {
        true => s.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => s,
    }
}

/// A relative error as a percentage to three significant digits.
fn percent(v: f64) -> String {
    if v.is_finite() {
        format!("{} %", sig(100.0 * v, 3))
    } else {
        "–".into()
    }
}

fn optional(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or("–".into(), f)
}

fn convergence(source: &Path) -> Result<Table> {
    let rows: Vec<convergence::Row> = table::read_rows(source)?;
    let mut t = Table::new(&[
        "frame",
        "H/δr",
        "particles",
        "steps",
        "L2 mean",
        "L2 final",
        "order",
        WALL,
    ]);
    for r in rows {
        t.rows.push(vec![
            r.frame,
            r.resolution.to_string(),
            r.particles.to_string(),
            r.steps.to_string(),
            percent(r.l2_mean),
            percent(r.l2_final),
            optional(r.order, |o| format!("{o:.2}")),
            sig(r.wall_seconds, 3),
        ]);
    }
    Ok(t)
}

/// One row per variant, one column per Wi: the time-mean L2 error of a stable run, the
/// error of an inaccurate one, the time of a breakdown.
fn stability(source: &Path) -> Result<Table> {
    let rows: Vec<stability::Row> = table::read_rows(source)?;
    let mut wis: Vec<f64> = Vec::new();
    let mut variants: Vec<String> = Vec::new();
    for r in &rows {
        if !wis.contains(&r.wi) {
            wis.push(r.wi);
        }
        if !variants.contains(&r.variant) {
            variants.push(r.variant.clone());
        }
    }
    let mut header = vec!["variant".to_string()];
    header.extend(wis.iter().map(|w| format!("Wi = {w}")));
    let mut t = Table {
        header,
        rows: Vec::new(),
    };
    for v in &variants {
        let mut line = vec![v.clone()];
        for &wi in &wis {
            let r = rows.iter().find(|r| &r.variant == v && r.wi == wi);
            line.push(r.map_or("–".into(), stability_cell));
        }
        t.rows.push(line);
    }
    Ok(t)
}

fn stability_cell(r: &stability::Row) -> String {
    let l2 = optional(r.l2_mean, percent);
    match r.outcome {
        stability::Result3::Stable => l2,
        stability::Result3::Inaccurate => format!("inaccurate, {l2}"),
        stability::Result3::BrokeDown => {
            format!("broke down, t = {}", optional(r.t_breakdown, |t| sig(t, 3)))
        }
        other => other.name().into(),
    }
}

fn speed_accuracy(source: &Path) -> Result<Table> {
    let rows: Vec<speed_accuracy::Point> = table::read_rows(source)?;
    let mut t = Table::new(&[
        "run",
        "particles",
        "steps",
        "L2 mean",
        "L2 final",
        "Pareto",
        WALL,
    ]);
    for r in rows {
        t.rows.push(vec![
            r.label,
            r.particles.to_string(),
            r.steps.to_string(),
            percent(r.l2_mean),
            percent(r.l2_final),
            if r.pareto { "yes" } else { "" }.into(),
            sig(r.wall_seconds, 3),
        ]);
    }
    Ok(t)
}

fn cylinder(source: &Path) -> Result<Table> {
    let rows: Vec<cylinder::Row> = table::read_rows(source)?;
    let mut t = Table::new(&[
        "Wi",
        "R/δr",
        "outcome",
        "K",
        "K pressure, solvent, polymer",
        "peak τ_xx on the centre-line",
        "min det A",
        "particles",
        "steps",
        WALL,
    ]);
    for r in rows {
        // A broken run's drag and stresses are those of the state that broke: not results.
        let broke = r.outcome == "BrokeDown";
        let value = |v: f64, digits: i32| if broke { "–".into() } else { sig(v, digits) };
        t.rows.push(vec![
            format!("{}", r.wi),
            short(r.radius_over_dr),
            if broke {
                "broke down".into()
            } else {
                r.outcome.to_lowercase()
            },
            value(r.drag_k, 5),
            format!(
                "{}, {}, {}",
                value(r.k_pressure, 4),
                value(r.k_solvent, 4),
                value(r.k_polymer, 4)
            ),
            value(r.peak_tau_xx, 4),
            value(r.min_det_a, 4),
            r.particles.to_string(),
            r.steps.to_string(),
            sig(r.wall_seconds, 3),
        ]);
    }
    Ok(t)
}

/// A run's `summary.json`, read by field name: a summary written before a field existed
/// shows `–` there.
struct Summary {
    value: serde_json::Value,
    dir: PathBuf,
}

impl Summary {
    fn read(dir: &Path) -> Result<Summary> {
        let path = dir.join("summary.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let value =
            serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
        Ok(Summary {
            value,
            dir: dir.to_path_buf(),
        })
    }

    fn num(&self, pointer: &str) -> f64 {
        let v = self.value.pointer(pointer);
        v.and_then(|v| v.as_f64()).unwrap_or(f64::NAN)
    }

    fn text(&self, pointer: &str) -> String {
        let v = self.value.pointer(pointer).and_then(|v| v.as_str());
        v.unwrap_or("–").replace('_', " ")
    }

    /// The run directory as the page names it (the last component for a source given as
    /// a path from the root).
    fn name(&self, root: &Path) -> String {
        let dir = self.dir.strip_prefix(root).unwrap_or(&self.dir);
        format!("`{}`", dir.display())
    }
}

/// One row per run of a start-up flow: its velocity error over time against the reference.
fn runs(root: &Path, dirs: &[PathBuf]) -> Result<Table> {
    let mut t = Table::new(&[
        "run",
        "outcome",
        "t",
        "particles",
        "steps",
        "L2 mean",
        "L2 final",
        "u_c at the first overshoot",
        "τ_xy, τ_xx",
        WALL,
    ]);
    for dir in dirs {
        let s = Summary::read(dir)?;
        let overshoot = s.num("/errors/first_overshoot/u_centre");
        t.rows.push(vec![
            s.name(root),
            s.text("/outcome"),
            short(s.num("/t_reached")),
            short(s.num("/particles")),
            short(s.num("/steps")),
            percent(s.num("/errors/l2_time_mean")),
            percent(s.num("/errors/l2_final")),
            signed_percent(overshoot / s.num("/errors/first_overshoot/u_centre_exact") - 1.0),
            format!(
                "{}, {}",
                percent(s.num("/errors/tau_xy_relative_l2")),
                percent(s.num("/errors/tau_xx_relative_l2"))
            ),
            sig(s.num("/wall_seconds"), 3),
        ]);
    }
    Ok(t)
}

/// One row per run to a steady state: the relative L2 errors of its fields at the end.
fn steady(root: &Path, dirs: &[PathBuf]) -> Result<Table> {
    let mut t = Table::new(&[
        "run",
        "model",
        "H/δr",
        "viscosity",
        "t",
        "steps",
        "u",
        "τ_xy",
        "τ_xx",
        "τ_yy",
        WALL,
    ]);
    for dir in dirs {
        let s = Summary::read(dir)?;
        t.rows.push(vec![
            s.name(root),
            s.text("/case/fluid/model"),
            short(s.num("/case/scene/resolution")),
            s.text("/derived/viscosity"),
            short(s.num("/t_reached")),
            short(s.num("/steps")),
            percent(s.num("/errors/u_relative_l2")),
            percent(s.num("/errors/tau_xy_relative_l2")),
            percent(s.num("/errors/tau_xx_relative_l2")),
            percent(s.num("/errors/tau_yy_relative_l2")),
            sig(s.num("/wall_seconds"), 3),
        ]);
    }
    Ok(t)
}

/// One row per run directory, one column per `(name, JSON pointer)` of its `summary.json`:
/// numbers as [`short`] writes them, strings as they are.
fn values(root: &Path, dirs: &[PathBuf], columns: &[(String, String)]) -> Result<Table> {
    let mut header = vec!["run"];
    header.extend(columns.iter().map(|(name, _)| name.as_str()));
    let mut t = Table::new(&header);
    for dir in dirs {
        let s = Summary::read(dir)?;
        let mut row = vec![s.name(root)];
        for (_, pointer) in columns {
            // A pointer ending in `%` is a fraction shown as a percentage.
            if let Some(fraction) = pointer.strip_suffix('%') {
                row.push(percent(s.num(fraction)));
                continue;
            }
            row.push(match s.value.pointer(pointer) {
                Some(serde_json::Value::Number(n)) if n.is_u64() => n.to_string(),
                Some(serde_json::Value::Number(n)) => short(n.as_f64().unwrap_or(f64::NAN)),
                Some(serde_json::Value::String(text)) => text.replace('_', " "),
                Some(serde_json::Value::Bool(b)) => b.to_string(),
                _ => "–".into(),
            });
        }
        t.rows.push(row);
    }
    Ok(t)
}

/// The named columns of the CSV file `source`, numbers as [`short`] writes them.
fn columns(source: &Path, columns: &[(String, String)]) -> Result<Table> {
    let rows: Vec<std::collections::BTreeMap<String, String>> = table::read_rows(source)?;
    let mut header = vec!["row"];
    header.extend(columns.iter().map(|(name, _)| name.as_str()));
    let mut t = Table::new(&header);
    for (k, row) in rows.iter().enumerate() {
        let mut line = vec![(k + 1).to_string()];
        for (name, column) in columns {
            let cell = row.get(column).with_context(|| {
                format!(
                    "{} has no column `{column}` (for `{name}`)",
                    source.display()
                )
            })?;
            line.push(match cell.parse::<f64>() {
                Ok(v) => short(v),
                Err(_) => cell.clone(),
            });
        }
        t.rows.push(line);
    }
    Ok(t)
}

fn signed_percent(v: f64) -> String {
    match percent(v) {
        p if v > 0.0 => format!("+{p}"),
        p => p,
    }
}

/// A marked block of a page: where it is, what it tabulates, and the table committed there.
struct Block {
    /// Line indices of the opening and closing markers.
    open: usize,
    close: usize,
    kind: Kind,
    sources: Vec<PathBuf>,
    /// `name=/json/pointer` (the `values` kind) or `name=column` (the `columns` kind).
    columns: Vec<(String, String)>,
    /// The marker's text after `generated:`, for messages.
    label: String,
}

impl Block {
    fn generate(&self, root: &Path) -> Result<Table> {
        let at = |p: &PathBuf| root.join(p);
        let one = || -> Result<PathBuf> {
            match self.sources.as_slice() {
                [s] => Ok(at(s)),
                _ => bail!("`{}` takes one source file", self.label),
            }
        };
        match self.kind {
            Kind::Convergence => convergence(&one()?),
            Kind::Stability => stability(&one()?),
            Kind::SpeedAccuracy => speed_accuracy(&one()?),
            Kind::Cylinder => cylinder(&one()?),
            Kind::Runs => runs(root, &self.sources.iter().map(at).collect::<Vec<_>>()),
            Kind::Steady => steady(root, &self.sources.iter().map(at).collect::<Vec<_>>()),
            Kind::Values => {
                let dirs = self.sources.iter().map(at).collect::<Vec<_>>();
                values(root, &dirs, &self.columns)
            }
            Kind::Columns => columns(&one()?, &self.columns),
        }
    }
}

/// The marked blocks of a page's `lines`.
fn blocks(lines: &[&str], page: &str) -> Result<Vec<Block>> {
    let mut found = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let Some(rest) = lines[i].trim().strip_prefix(OPEN) else {
            i += 1;
            continue;
        };
        let label = rest.trim_end_matches("-->").trim().to_string();
        let mut words = label.split_whitespace();
        let kind = words
            .next()
            .and_then(Kind::parse)
            .with_context(|| format!("{page}:{}: unknown table kind in `{label}`", i + 1))?;
        let (columns, sources): (Vec<&str>, Vec<&str>) = words.partition(|w| w.contains('='));
        let columns = columns
            .iter()
            .filter_map(|w| w.split_once('='))
            .map(|(name, pointer)| (name.replace('_', " "), pointer.to_string()))
            .collect();
        let sources = sources.into_iter().map(PathBuf::from).collect();
        let close = (i + 1..lines.len())
            .find(|&j| lines[j].trim() == CLOSE)
            .with_context(|| format!("{page}:{}: `{label}` has no `{CLOSE}`", i + 1))?;
        found.push(Block {
            open: i,
            close,
            kind,
            sources,
            columns,
            label,
        });
        i = close + 1;
    }
    Ok(found)
}

/// Every cell of `committed` that `regenerated` contradicts, wall-clock columns aside.
fn compare(committed: &Table, regenerated: &Table) -> Vec<String> {
    if committed.header != regenerated.header || committed.rows.len() != regenerated.rows.len() {
        return vec![format!(
            "the table's shape changed ({} rows of `{}` committed, {} rows of `{}` regenerated)",
            committed.rows.len(),
            committed.header.join(" | "),
            regenerated.rows.len(),
            regenerated.header.join(" | ")
        )];
    }
    let mut found = Vec::new();
    for (n, (old, new)) in committed.rows.iter().zip(&regenerated.rows).enumerate() {
        for (c, name) in regenerated.header.iter().enumerate() {
            let (a, b) = (old.get(c), new.get(c));
            if name != WALL && a != b {
                found.push(format!(
                    "row {} (`{}`), column `{name}`: committed {}, regenerated {}",
                    n + 1,
                    new[0],
                    a.map_or("nothing", |s| s.as_str()),
                    b.map_or("nothing", |s| s.as_str()),
                ));
            }
        }
    }
    found
}

/// What regenerating the pages found: committed numbers their sources contradict, and
/// results typed outside the generated tables (see [`typed`]).
#[derive(Debug, Default)]
pub struct Findings {
    pub contradictions: Vec<Contradiction>,
    /// `page:line: number` of each typed result.
    pub typed: Vec<String>,
}

/// Regenerates the marked tables of `pages` (one Markdown page, or every page of a
/// directory; sources relative to `root`); writes the pages unless `check`.
pub fn regenerate(root: &Path, pages: &Path, check: bool) -> Result<Findings> {
    let mut files: Vec<PathBuf> = if pages.is_file() {
        vec![pages.to_path_buf()]
    } else {
        std::fs::read_dir(pages)
            .with_context(|| format!("reading {}", pages.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "md"))
            .collect()
    };
    files.sort();
    let mut found = Findings::default();
    for page in files {
        let text = std::fs::read_to_string(&page)
            .with_context(|| format!("reading {}", page.display()))?;
        let (rewritten, mut contradictions) = regenerate_page(root, &page, &text)?;
        found.contradictions.append(&mut contradictions);
        found.typed.extend(
            typed::typed_numbers(&text)
                .into_iter()
                .map(|t| format!("{}:{}: {}", page.display(), t.line, t.number)),
        );
        if !check && rewritten != text {
            crate::app::io::write_atomic(&page, rewritten.as_bytes())?;
        }
    }
    Ok(found)
}

/// The page `text` with its marked tables regenerated, and what they contradicted.
fn regenerate_page(root: &Path, page: &Path, text: &str) -> Result<(String, Vec<Contradiction>)> {
    let name = page.display().to_string();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = String::with_capacity(text.len());
    let mut found = Vec::new();
    let mut next = 0;
    for b in blocks(&lines, &name)? {
        let table = b
            .generate(root)
            .with_context(|| format!("{name}:{}: `{}`", b.open + 1, b.label))?;
        let committed = Table::parse(&lines[b.open + 1..b.close]);
        found.extend(
            compare(&committed, &table)
                .into_iter()
                .map(|what| Contradiction {
                    place: format!("{name}:{}", b.open + 1),
                    block: b.label.clone(),
                    what,
                }),
        );
        for line in &lines[next..=b.open] {
            let _ = writeln!(out, "{line}");
        }
        out += &table.markdown();
        next = b.close;
    }
    for line in &lines[next..] {
        let _ = writeln!(out, "{line}");
    }
    Ok((out, found))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_their_significant_digits_without_exponents() {
        assert_eq!(sig(0.0031683, 3), "0.00317");
        assert_eq!(sig(1.1916e-7, 3), "1.19e-7");
        assert_eq!(sig(117.7834, 5), "117.78");
        assert_eq!(sig(2663.0, 3), "2663");
        assert_eq!(percent(3.168346e-3), "0.317 %");
        assert_eq!(
            (short(5.0), short(4.3504), short(39941.0)),
            ("5".into(), "4.35".into(), "39941".into())
        );
        assert_eq!(percent(f64::NAN), "–");
        assert_eq!(signed_percent(0.0134), "+1.34 %");
    }

    /// A block regenerated from a source file, then a number of it changed by hand: the
    /// check names the row and column; a changed wall time is not a contradiction.
    #[test]
    fn a_committed_number_the_source_contradicts_is_flagged() {
        let dir = tempfile::tempdir().unwrap();
        let csv = "frame,resolution,spacing,particles,steps,wall_seconds,l2_mean,l2_final,order\n\
                   lagrangian,15,6.6e-2,225,666,1.516,1.299005e-2,2.909372e-3,\n\
                   lagrangian,30,3.3e-2,900,2663,15.780,3.168346e-3,5.020761e-4,2.036\n";
        std::fs::write(dir.path().join("c.csv"), csv).unwrap();
        let page = dir.path().join("p.md");
        let text = format!("# P\n\n{OPEN} convergence c.csv -->\n{CLOSE}\nafter\n");
        let (fresh, found) = regenerate_page(dir.path(), &page, &text).unwrap();
        assert_eq!(
            found.len(),
            1,
            "an empty block has the wrong shape: {found:?}"
        );
        assert!(
            fresh.contains("| lagrangian | 30 | 900 | 2663 | 0.317 % | 0.0502 % | 2.04 | 15.8 |")
        );
        assert!(fresh.ends_with(&format!("{CLOSE}\nafter\n")));
        let (again, found) = regenerate_page(dir.path(), &page, &fresh).unwrap();
        assert!(found.is_empty() && again == fresh);
        let timed = fresh.replace("| 15.8 |", "| 99 |");
        assert!(regenerate_page(dir.path(), &page, &timed)
            .unwrap()
            .1
            .is_empty());
        let doctored = fresh.replace("0.317 %", "0.300 %");
        let found = regenerate_page(dir.path(), &page, &doctored).unwrap().1;
        assert_eq!(found.len(), 1);
        assert!(found[0]
            .what
            .contains("row 2 (`lagrangian`), column `L2 mean`"));
        assert!(found[0]
            .what
            .contains("committed 0.300 %, regenerated 0.317 %"));
    }

    /// The `values` kind reads the named fields of each run's summary, numbers to four
    /// significant digits; a field the summary lacks shows `–`.
    #[test]
    fn values_take_the_named_fields_of_each_summary() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path().join("run");
        std::fs::create_dir(&run).unwrap();
        let summary = r#"{"outcome": "finished", "discs": [{"rotation_ratio": 0.977123}]}"#;
        std::fs::write(run.join("summary.json"), summary).unwrap();
        let page = dir.path().join("p.md");
        let marker = "values run ratio=/discs/0/rotation_ratio missing_one=/nothing r=/discs/0/rotation_ratio%";
        let text = format!("{OPEN} {marker} -->\n{CLOSE}\n");
        let (fresh, _) = regenerate_page(dir.path(), &page, &text).unwrap();
        assert!(
            fresh.contains("| run | ratio | missing one | r |"),
            "{fresh}"
        );
        assert!(fresh.contains("| `run` | 0.9771 | – | 97.7 % |"), "{fresh}");
    }

    /// The `columns` kind reads the named columns of a CSV file by header; a column the file
    /// lacks is an error naming it.
    #[test]
    fn columns_take_the_named_columns_of_a_csv() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("b.csv"), "n,step_ms,note\n1024,0.89940,a\n").unwrap();
        let page = dir.path().join("p.md");
        let text = format!("{OPEN} columns b.csv N=n step=step_ms what=note -->\n{CLOSE}\n");
        let (fresh, _) = regenerate_page(dir.path(), &page, &text).unwrap();
        assert!(fresh.contains("| row | N | step | what |"), "{fresh}");
        assert!(fresh.contains("| 1 | 1024 | 0.8994 | a |"), "{fresh}");
        let text = format!("{OPEN} columns b.csv N=count -->\n{CLOSE}\n");
        let error = format!(
            "{:#}",
            regenerate_page(dir.path(), &page, &text).unwrap_err()
        );
        assert!(error.contains("no column `count`"), "{error}");
    }
}
