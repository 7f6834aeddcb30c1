//! The `impact` command line: subcommands only, no mechanics.

use clap::{Parser, Subcommand};
use impact::analysis::{self, RunError, RunOptions};
use impact::scene;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "impact",
    version,
    about = "Finite-strain elastoplastic contact-impact in 2D and 1D"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene: VTK frames, history.csv and summary.json in the output folder.
    Run {
        scene: PathBuf,
        /// Output folder. Default: output/<scene name>/
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene value before it is read, e.g. --set analysis.steps=20
        /// or --set body.beam.velocity=[0,-1] (arrays of tables addressed by name).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bar and no closing line.
        #[arg(long)]
        quiet: bool,
    },
    /// Validate a scene and print the model's size.
    Check {
        scene: PathBuf,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            set,
            quiet,
        } => run(&scene, out, &set, quiet),
        Command::Check { scene, set } => check(&scene, &set),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn run(path: &Path, out: Option<PathBuf>, set: &[String], quiet: bool) -> Result<(), RunError> {
    let model = scene::load(path, set)?;
    let dir = out.unwrap_or_else(|| PathBuf::from("output").join(&model.name));
    let options = RunOptions {
        progress: !quiet && std::io::stderr().is_terminal(),
    };
    let summary = analysis::run(&model, &dir, options)?;
    if !quiet {
        println!(
            "{}: {} steps, {} Newton iterations, {} factorizations, {:.2} s -> {}",
            model.name,
            summary.steps,
            summary.newton_iterations,
            summary.factorizations,
            summary.wall_seconds,
            dir.display()
        );
    }
    Ok(())
}

fn check(path: &Path, set: &[String]) -> Result<(), RunError> {
    let model = scene::load(path, set)?;
    println!("{}: valid", path.display());
    for body in &model.bodies {
        println!(
            "  body `{}`: {} nodes, {} elements, {:?}, material `{}`",
            body.name,
            body.mesh.nodes.len(),
            body.elements(),
            body.kind,
            body.material.name
        );
    }
    println!(
        "  total: {} nodes, {} elements, {} DOFs",
        model.node_count,
        model.elements(),
        model.dofs()
    );
    if model.bodies.iter().all(|b| b.material.density > 0.0) {
        let (dt_crit, b, e) = analysis::explicit::critical_time_step(&model)?;
        println!(
            "  central-difference stability limit: dt_crit = {dt_crit:.6e} (element eigenvalue bound; body `{}`, element {e})",
            model.bodies[b].name
        );
    }
    Ok(())
}
