//! A study's members run elsewhere: `--emit DIR` writes each member's case file into its run
//! directory and the scripts that run them (a Slurm job array, a plain `xargs` line);
//! `--collect DIR` reads the finished members back and assembles the study as if it had run
//! them itself. A member is finished when its directory holds a `summary.json` and the
//! `case.toml` the run wrote equals the member's case, the same test as `--reuse`, so a
//! member run by hand, by a scheduler or by `--jobs` counts alike. A member not finished is
//! a `lost` or `failed` row of the table, and the command ends with [`Incomplete`].

use super::{member_dir, read_finished, Executor, Members, Missing, Variant};
use crate::app::io::write_atomic;
use crate::app::run::{CASE_FILE, ERROR_FILE};
use crate::setup::case::Case;
use anyhow::{bail, Context, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The member list, one run directory per line (relative to the study's directory).
pub const MEMBERS: &str = "members.txt";

/// What `--emit` wrote: not an error, but the study stops there (nothing to assemble yet).
#[derive(Debug)]
pub struct Emitted {
    pub members: usize,
    pub dir: String,
}

impl std::fmt::Display for Emitted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{n} members written to {d}/{MEMBERS}; run them with {d}/run-members.sh (here, \
             `--jobs` at a time) or `cd {d} && sbatch job-array.slurm`, then repeat the study's \
             command with `--collect {d}`",
            n = self.members,
            d = self.dir
        )
    }
}

impl std::error::Error for Emitted {}

/// Writes each member's `case.toml` and the scripts that run them.
pub fn emit(variants: &[Variant], cases: &[Case], out: &Path) -> Result<Emitted> {
    let mut list = String::new();
    for (variant, case) in variants.iter().zip(cases) {
        if let Some(from) = &variant.from {
            bail!(
                "--emit: member `{}` starts from another member's state ({}); grid sequencing \
                 (--sequence) runs its stages in order, so run this study here with --jobs",
                variant.label,
                from.display()
            );
        }
        let dir = member_dir(out, variant);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        write_atomic(
            &dir.join(CASE_FILE),
            toml::to_string(&case.source)?.as_bytes(),
        )?;
        let relative = dir.strip_prefix(out).unwrap_or(&dir);
        let _ = writeln!(list, "{}", relative.display());
    }
    write_atomic(&out.join(MEMBERS), list.as_bytes())?;
    write_script(&out.join("run-members.sh"), &local_script())?;
    write_script(&out.join("job-array.slurm"), &slurm_script(variants.len()))?;
    Ok(Emitted {
        members: variants.len(),
        dir: out.display().to_string(),
    })
}

/// One member's command, `$RHEOSPH` being the program (default `rheosph` on the PATH).
/// A member that holds a `summary.json` has finished (or broken down, which is a result too)
/// and is skipped, so a rerun after a lost member runs only what is missing.
const MEMBER: &str = "[ -e \"$m/summary.json\" ] || \"$RHEOSPH\" run \"$m/case.toml\" --out \"$m\" --no-snapshots --no-charts";

fn local_script() -> String {
    format!(
        "#!/usr/bin/env bash\n\
         # Runs every member of this study not yet finished, JOBS at a time (default 2).\n\
         #   RHEOSPH=path/to/rheosph JOBS=4 ./run-members.sh\n\
         set -euo pipefail\n\
         cd \"$(dirname \"$0\")\"\n\
         export RHEOSPH=\"${{RHEOSPH:-rheosph}}\"\n\
         xargs -P \"${{JOBS:-2}}\" -I{{}} sh -c 'm=\"$1\"; {member} > \"$m/log.txt\" 2>&1 || echo \"member $m: exit $?\"' _ {{}} < {MEMBERS}\n",
        member = MEMBER
    )
}

fn slurm_script(n: usize) -> String {
    format!(
        "#!/usr/bin/env bash\n\
         # One array task per member of this study (line k + 1 of {MEMBERS}).\n\
         #   sbatch job-array.slurm        (from this directory; set RHEOSPH if needed)\n\
         #SBATCH --job-name=rheosph-study\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task=2\n\
         #SBATCH --output=slurm-%A_%a.out\n\
         set -euo pipefail\n\
         cd \"${{SLURM_SUBMIT_DIR:-$(dirname \"$0\")}}\"\n\
         RHEOSPH=\"${{RHEOSPH:-rheosph}}\"\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-1}}\"\n\
         m=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {MEMBERS})\n\
         {member}\n",
        last = n.saturating_sub(1),
        member = MEMBER
    )
}

fn write_script(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, text.as_bytes())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
            .with_context(|| format!("making {} executable", path.display()))?;
    }
    Ok(())
}

/// Every member's finished run, and the members without one (`lost`, or `failed` with the
/// error its run recorded).
pub fn collect(variants: Vec<Variant>, cases: Vec<Case>, out: &Path) -> Result<Members> {
    let mut members = Members {
        finished: Vec::new(),
        missing: Vec::new(),
        executor: Executor::Collect,
    };
    for (index, (variant, case)) in variants.into_iter().zip(cases).enumerate() {
        let dir = member_dir(out, &variant);
        match read_finished(variant, case, &dir)? {
            Ok(done) => members.finished.push(done),
            Err((variant, case)) => {
                let error = std::fs::read_to_string(dir.join(ERROR_FILE))
                    .ok()
                    .map(|e| e.trim().to_string());
                members.missing.push(Missing {
                    variant,
                    case,
                    dir,
                    index,
                    error,
                });
            }
        }
    }
    Ok(members)
}

/// Members of a study did not finish: the study's table is written (a `lost` or `failed` row
/// each), and the command exits with [`EXIT_INCOMPLETE`](crate::app::cli::EXIT_INCOMPLETE).
#[derive(Debug)]
pub struct Incomplete {
    /// Each missing member: its run directory and outcome (with the error, if it failed).
    pub missing: Vec<String>,
    /// Their lines in `members.txt`, from 0.
    pub indices: Vec<usize>,
    pub members: usize,
    pub dir: String,
    /// Where the members ran: the advice on running only these differs.
    pub executor: Executor,
}

impl Incomplete {
    /// Ok if no member is missing; else the error naming them.
    pub fn check(
        missing: &[Missing],
        members: usize,
        out: &Path,
        executor: Executor,
    ) -> Result<()> {
        if missing.is_empty() {
            return Ok(());
        }
        Err(Incomplete {
            missing: missing
                .iter()
                .map(|m| match &m.error {
                    Some(e) => format!("{}: failed: {e}", m.dir.display()),
                    None => format!("{}: lost", m.dir.display()),
                })
                .collect(),
            indices: missing.iter().map(|m| m.index).collect(),
            members,
            dir: out.display().to_string(),
            executor,
        }
        .into())
    }
}

impl std::fmt::Display for Incomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (n, m, list) = (self.missing.len(), self.members, self.missing.join("\n  "));
        if self.executor == Executor::Here {
            return write!(
                f,
                "{n} of {m} members did not finish; the table has a `failed` row for each (the \
                 error is also in its run directory's error.txt):\n  {list}\n\
                 To run only these, repeat this command with --reuse"
            );
        }
        let indices: Vec<String> = self.indices.iter().map(usize::to_string).collect();
        write!(
            f,
            "--collect: {n} of {m} members have not finished; the table has a row for each \
             (outcome `lost`: no summary.json, or a case.toml that is not this study's; \
             `failed`: its run stopped on an error):\n  {list}\n\
             To resume, run only these, then repeat this command:\n  \
             {d}/run-members.sh\n  \
             cd {d} && sbatch --array={indices} job-array.slurm",
            d = self.dir,
            indices = indices.join(","),
        )
    }
}

impl std::error::Error for Incomplete {}
