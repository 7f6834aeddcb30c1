//! The scenes of `impact bench --scenes`: every scene in models/ as it is shipped, run as a
//! child process like the other cases, so that a change that slows a scene a user runs (more
//! steps, iterations, factorizations or memory) shows in one table and in bench.json.

use super::{Bottom, Case, Method, SceneCase};
use crate::scene::model::Analysis;
use crate::scene::spec::{IntegratorKind, Quadrature};
use std::path::Path;

/// One case per `*.toml` of `models`, in name order; the method is the scene's (statics and
/// every implicit integrator count as `implicit`). A scene that does not load is an error
/// naming it.
pub fn cases(models: &Path) -> Result<Vec<Case>, String> {
    let listing = std::fs::read_dir(models)
        .map_err(|e| format!("{}: cannot list the scenes: {e}", models.display()))?;
    let mut files: Vec<_> = listing
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|file| {
            let model = crate::scene::load(&file, &[]).map_err(|e| e.to_string())?;
            let method = match &model.analysis {
                Analysis::Dynamic(d) if d.integrator == IntegratorKind::CentralDifference => {
                    match d.quadrature {
                        Quadrature::Reduced => Method::ExplicitReduced,
                        Quadrature::Full => Method::Explicit,
                    }
                }
                _ => Method::Implicit,
            };
            Ok(Case {
                name: format!("scene_{}", model.name),
                method,
                n: 0,
                steps: 0,
                bottom: Bottom::Free,
                frame_every: 0,
                threads: None,
                speed: 0.0,
                strategy: "modified",
                scene: Some(SceneCase {
                    file,
                    overrides: vec!["output.frame_every=0".to_string()],
                }),
            })
        })
        .collect()
}
