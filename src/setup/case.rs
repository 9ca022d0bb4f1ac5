//! Case files: [`load`] and [`parse`] read one with `--set` overrides into a validated
//! [`Case`] (the scene, the fluid, the scheme and the run's settings, each checked once;
//! nothing downstream re-checks strings or ranges). Every error names the file and the dotted
//! field.

pub use crate::setup::derived::Derived;
pub use crate::setup::error::CaseError;
use crate::setup::overrides::apply_override;
pub use crate::setup::schema::CaseFile;
pub use crate::setup::validate::{Case, SteadyCriterion, SteadySignal};
use std::path::Path;

/// Reads, overrides and validates a case file.
pub fn load(path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| CaseError {
        file: file.clone(),
        field: String::new(),
        message: format!("cannot read: {e}"),
    })?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "case".into());
    parse(&text, &file, &name, overrides)
}

/// Parses case text (see [`load`]).
pub fn parse(text: &str, file: &str, name: &str, overrides: &[String]) -> Result<Case, CaseError> {
    let err = |field: &str, message: String| CaseError {
        file: file.to_string(),
        field: field.to_string(),
        message,
    };
    let mut table: toml::Table = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
        let message = e.message().trim().replace('\n', "; ");
        match line {
            Some(l) => err("", format!("not valid TOML at line {l}: {message}")),
            None => err("", format!("not valid TOML: {message}")),
        }
    })?;
    for o in overrides {
        apply_override(&mut table, o).map_err(|m| err("", format!("--set {o:?}: {m}")))?;
    }
    let raw = CaseFile::from_table(table).map_err(|(field, message)| err(&field, message))?;
    crate::setup::validate::validate(raw, name).map_err(|(field, message)| err(&field, message))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::frame::Frame;

    const POISEUILLE: &str = include_str!("../../cases/poiseuille.toml");

    #[test]
    fn shipped_case_is_valid_with_paper_parameters() {
        let case = parse(POISEUILLE, "poiseuille.toml", "poiseuille", &[]).unwrap();
        let d = case.derived();
        assert!((d.reynolds - 1.0).abs() < 1e-12);
        assert!((d.weissenberg - 1.0).abs() < 1e-12);
        assert_eq!(d.particles, 900);
        assert_eq!(case.fluid.beta, 0.1);
    }

    #[test]
    fn overrides_reach_any_dotted_key() {
        let case = parse(
            POISEUILLE,
            "p.toml",
            "p",
            &[
                "fluid.beta=0.3".into(),
                "scheme.frame=eulerian".into(),
                "scene.resolution=15".into(),
            ],
        )
        .unwrap();
        assert_eq!(case.fluid.beta, 0.3);
        assert_eq!(case.scheme.frame, Frame::Eulerian);
        assert_eq!(case.scene.resolution(), 15);
    }

    #[test]
    fn errors_name_the_file_and_field() {
        let e = parse(POISEUILLE, "p.toml", "p", &["fluid.beta=1.5".into()]).unwrap_err();
        assert_eq!(e.field, "fluid.beta");
        assert!(
            e.to_string().starts_with("p.toml: field `fluid.beta`"),
            "{e}"
        );
        let e = parse(POISEUILLE, "p.toml", "p", &["fluid.colour=3".into()]).unwrap_err();
        assert!(e.to_string().contains("colour"), "{e}");
        let e = parse(POISEUILLE, "p.toml", "p", &["nonsense".into()]).unwrap_err();
        assert!(e.to_string().contains("--set"), "{e}");
    }

    /// A key of another scene kind is named as `scene.<key>`, as a misplaced model
    /// parameter is named as `fluid.<key>`.
    #[test]
    fn misplaced_keys_are_named() {
        let e = parse(POISEUILLE, "p.toml", "p", &["scene.drop.diameter=1".into()]).unwrap_err();
        assert_eq!(e.field, "scene.drop", "{e}");
        let e = parse(POISEUILLE, "p.toml", "p", &["fluid.alpha=0.2".into()]).unwrap_err();
        assert_eq!(e.field, "fluid.alpha", "{e}");
        assert!(e.message.contains("oldroyd-b"), "{e}");
    }
}
