//! Scenes: TOML files deserialized with serde (`deny_unknown_fields` everywhere), edited by
//! `--set KEY=VALUE` before deserializing, then validated into a [`Model`].
//!
//! Every field's default is written next to it and collected in docs/user-guide.md.
//! Validation never clamps: a value out of range is an [`InputError`] naming the file and key.

mod analysis;
mod bodies;
mod contacts;
mod context;
mod loads;
mod materials;
pub mod model;
mod obstacles;
pub mod overrides;
mod probes;
mod reference;
mod roles;
pub mod spec;
pub mod validate;

pub use model::{
    Body, BodyKind, Continuum, Curve, DynamicAnalysis, Load, Model, SceneSource, StaticAnalysis,
};
pub use spec::Scene;

use std::path::{Path, PathBuf};

/// Bad input: the message names the file and the key (or element / set) and what was expected.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{file}: {message}")]
pub struct InputError {
    pub file: String,
    pub message: String,
}

impl InputError {
    pub fn new(file: &Path, message: impl Into<String>) -> InputError {
        InputError {
            file: file.display().to_string(),
            message: message.into(),
        }
    }
}

/// Reads a scene file, applies the `--set` overrides, deserializes and validates it.
pub fn load(path: &Path, overrides: &[String]) -> Result<Model, InputError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, format!("cannot read the scene: {e}")))?;
    from_str(&text, path, overrides)
}

/// As [`load`], from the scene's text; `path` names it in messages and anchors relative mesh files.
pub fn from_str(text: &str, path: &Path, overrides: &[String]) -> Result<Model, InputError> {
    let scene: Scene = if overrides.is_empty() {
        // from the text itself, so messages point at the file's own lines
        toml::from_str(text).map_err(|e: toml::de::Error| InputError::new(path, e.to_string()))?
    } else {
        let mut table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| InputError::new(path, e.to_string()))?;
        for assignment in overrides {
            overrides::apply(&mut table, assignment)
                .map_err(|m| InputError::new(path, format!("--set {assignment}: {m}")))?;
        }
        let edited = toml::to_string(&table).expect("a TOML table serializes");
        // the edited text is not the user's file: its line numbers would mislead, so only
        // the message (which names the key or value) is given
        toml::from_str(&edited).map_err(|e: toml::de::Error| {
            InputError::new(
                path,
                format!(
                    "(as edited by --set {}) {}",
                    overrides.join(" --set "),
                    e.message()
                ),
            )
        })?
    };
    let base_dir: PathBuf = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut model = validate::build(scene, path, &base_dir)?;
    model.source = SceneSource {
        text: text.to_string(),
        overrides: overrides.to_vec(),
    };
    Ok(model)
}
