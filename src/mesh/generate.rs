//! Structured mesh generators (placeholder: being written).
use serde::Deserialize;
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum MeshSpec {}
