//! The Taylor benchmarks of `impact bench --case taylor`: two rods of models/ striking a rigid
//! wall, each on three meshes (twice as fine each time) with the one-point and the 2x2 explicit
//! kernels, each as a single-step, a subcycled (theory 8.7c) and a mass-scaled (8.7b) run, the
//! Johnson-Cook rod also with implicit Newmark; charts of the final shape against wall time
//! beside the published results, and of the error of L_f and D_f against the extrapolated
//! converged value against wall time for the three ways to step.

use super::{Bottom, Case, Method, Row, SceneCase};
use crate::output::OutputError;
use crate::output::plot::{self, Chart, Series, SeriesStyle};
use std::path::{Path, PathBuf};

/// A final-shape quantity of a Taylor run.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Measure {
    /// The rod's length, the extent of its final shape along the axis (mm).
    Length,
    /// The largest radius of its final shape (mm).
    Radius,
    /// Twice that (mm).
    Diameter,
    /// The equivalent plastic strain of the element on the axis at the wall.
    PlasticStrain,
    /// Its temperature (C).
    Temperature,
}

impl Measure {
    fn label(self) -> &'static str {
        match self {
            Measure::Length => "final length (mm)",
            Measure::Radius => "impact-face radius (mm)",
            Measure::Diameter => "impact-face diameter (mm)",
            Measure::PlasticStrain => "equivalent plastic strain, axis element at the wall",
            Measure::Temperature => "temperature, axis element at the wall (C)",
        }
    }

    fn file(self) -> &'static str {
        match self {
            Measure::Length => "length",
            Measure::Radius => "radius",
            Measure::Diameter => "diameter",
            Measure::PlasticStrain => "plastic_strain",
            Measure::Temperature => "temperature",
        }
    }
}

/// A published value drawn as a level on a chart.
struct Reference {
    label: &'static str,
    measure: Measure,
    value: f64,
}

/// One Taylor scene of models/ and what its study measures.
struct Benchmark {
    /// The scene's file stem, the prefix of its cases and charts.
    key: &'static str,
    title: &'static str,
    /// A short name for the charts with two panels.
    short: &'static str,
    /// The mesh has nx x (aspect nx) quads.
    aspect: usize,
    meshes: [usize; 3],
    /// The probes of the element on the axis at the wall (the rod's length and diameter
    /// are the scenes' `extent_y[all]` and `extent_x[all]`: the shape, wherever the rod
    /// ends, on the wall or lifted off it).
    element: Option<(&'static str, &'static str)>,
    /// Implicit Newmark average cases: dt on the coarsest mesh (halved with each refinement)
    /// and how many of the meshes (the finest takes many minutes).
    implicit: Option<(f64, usize)>,
    charts: &'static [Measure],
    references: Vec<Reference>,
    /// The mass scaling's target on the coarsest mesh (halved with each refinement, as the
    /// stable step is): about a quarter of the initial stable step.
    mass_scaling_target: f64,
}

/// How an explicit case steps: every element together, subcycled, or mass-scaled.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stepping {
    Single,
    Subcycled,
    MassScaled,
}

impl Stepping {
    const ALL: [Stepping; 3] = [Stepping::Single, Stepping::Subcycled, Stepping::MassScaled];

    /// The part of a case's name that says it (empty for the single step).
    fn tag(self) -> &'static str {
        match self {
            Stepping::Single => "",
            Stepping::Subcycled => "subcycled_",
            Stepping::MassScaled => "mass_scaled_",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Stepping::Single => "single step",
            Stepping::Subcycled => "subcycled",
            Stepping::MassScaled => "mass-scaled",
        }
    }

    /// The stepping of the row named `name`.
    fn of(name: &str) -> Stepping {
        if name.contains(Stepping::Subcycled.tag()) {
            Stepping::Subcycled
        } else if name.contains(Stepping::MassScaled.tag()) {
            Stepping::MassScaled
        } else {
            Stepping::Single
        }
    }
}

fn benchmarks() -> Vec<Benchmark> {
    vec![
        Benchmark {
            key: "taylor_aluminum",
            title: "Taylor impact, aluminium at 478 m/s",
            short: "Taylor aluminium",
            aspect: 6,
            meshes: [5, 10, 20],
            element: None,
            implicit: None,
            charts: &[Measure::Length, Measure::Radius],
            mass_scaling_target: 8e-9,
            references: vec![
                Reference {
                    label: "experiment (Wilkins & Guinan 1973)",
                    measure: Measure::Length,
                    value: 13.19,
                },
                Reference {
                    label: "ANSYS VMC8, lowest",
                    measure: Measure::Length,
                    value: 14.07,
                },
                Reference {
                    label: "ANSYS VMC8, highest",
                    measure: Measure::Length,
                    value: 14.22,
                },
            ],
        },
        Benchmark {
            key: "taylor_jc",
            title: "Taylor impact, 42CrMo4 Johnson-Cook at 287 m/s",
            short: "Taylor 42CrMo4 (Johnson-Cook)",
            aspect: 10,
            meshes: [5, 10, 20],
            element: Some(("eq_plastic_strain[face_centre]", "temperature[face_centre]")),
            implicit: Some((1.0e-7, 2)),
            charts: &[
                Measure::Length,
                Measure::Diameter,
                Measure::PlasticStrain,
                Measure::Temperature,
            ],
            mass_scaling_target: 2e-8,
            references: [
                (Measure::Length, 26.52, 26.56),
                (Measure::Diameter, 11.15, 11.16),
                (Measure::PlasticStrain, 1.78, 1.81),
                (Measure::Temperature, 582.34, 590.96),
            ]
            .into_iter()
            .flat_map(|(measure, dynela, abaqus)| {
                [
                    Reference {
                        label: "DynELA v4 (Pantale)",
                        measure,
                        value: dynela,
                    },
                    Reference {
                        label: "Abaqus/Explicit (Pantale)",
                        measure,
                        value: abaqus,
                    },
                ]
            })
            .collect(),
        },
    ]
}

/// The cases of both benchmarks: explicit one-point and 2x2 on every mesh, implicit where the
/// benchmark asks for it.
pub fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for b in benchmarks() {
        let file = PathBuf::from(format!("models/{}.toml", b.key));
        let case = |name: String, method: Method, nx: usize, extra: Vec<String>| {
            let mut overrides = vec![
                format!("body.rod.mesh.nx={nx}"),
                format!("body.rod.mesh.ny={}", b.aspect * nx),
                "output.frame_every=0".to_string(),
            ];
            overrides.extend(extra);
            scene_case(name, method, nx, file.clone(), overrides)
        };
        let mesh = |nx: usize| format!("{nx}x{}", b.aspect * nx);
        for (method, quadrature) in [
            (Method::ExplicitReduced, "reduced"),
            (Method::Explicit, "full"),
        ] {
            for stepping in Stepping::ALL {
                for nx in b.meshes {
                    let mut extra = vec![format!("analysis.quadrature={quadrature}")];
                    match stepping {
                        Stepping::Single => {}
                        Stepping::Subcycled => extra.push("analysis.subcycling={}".into()),
                        Stepping::MassScaled => extra.push(format!(
                            "analysis.mass_scaling.target={:e}",
                            b.mass_scaling_target * b.meshes[0] as f64 / nx as f64
                        )),
                    }
                    cases.push(case(
                        format!("{}_{quadrature}_{}{}", b.key, stepping.tag(), mesh(nx)),
                        method,
                        nx,
                        extra,
                    ));
                }
            }
        }
        if let Some((dt, count)) = b.implicit {
            for (k, nx) in b.meshes.iter().take(count).enumerate() {
                cases.push(case(
                    format!("{}_average_{}", b.key, mesh(*nx)),
                    Method::Implicit,
                    *nx,
                    vec![
                        "analysis.integrator=average".to_string(),
                        format!("analysis.dt={:e}", dt / f64::powi(2.0, k as i32)),
                    ],
                ));
            }
        }
    }
    cases.extend(rod_pair_cases());
    cases
}

/// Two rods striking each other (models/rod_on_rod.toml, mortar contact) and one of them on
/// a rigid wall (models/rod_wall.toml), one-point kernel, frames off: the pair should cost
/// about twice the single rod, its contact a small share of the run.
fn rod_pair_cases() -> Vec<Case> {
    [
        ("rod_on_rod", "rod_pair_reduced"),
        ("rod_wall", "rod_wall_reduced"),
    ]
    .into_iter()
    .map(|(file, name)| {
        let overrides = vec![
            "analysis.quadrature=reduced".to_string(),
            "output.frame_every=0".to_string(),
        ];
        let file = PathBuf::from(format!("models/{file}.toml"));
        scene_case(
            name.to_string(),
            Method::ExplicitReduced,
            5,
            file,
            overrides,
        )
    })
    .collect()
}

/// A case that runs the scene `file` with `overrides`; `n` is its mesh's elements across.
fn scene_case(
    name: String,
    method: Method,
    n: usize,
    file: PathBuf,
    overrides: Vec<String>,
) -> Case {
    Case {
        name,
        method,
        n,
        steps: 0,
        bottom: Bottom::Wall,
        frame_every: 0,
        threads: None,
        speed: 0.0,
        strategy: "modified",
        scene: Some(SceneCase { file, overrides }),
    }
}

/// The final value of `measure` in the run of row `r` (its history in `dir`).
fn finals(b: &Benchmark, dir: &Path, r: &Row) -> Result<Vec<(Measure, f64)>, OutputError> {
    let history = dir.join(&r.name).join("history.csv");
    let mut names = vec!["extent_y[all]", "extent_x[all]"];
    if let Some((strain, temperature)) = b.element {
        names.extend([strain, temperature]);
    }
    let columns = plot::history_columns(&history, &names)?;
    let last = |k: usize| *columns[k].last().unwrap_or(&f64::NAN);
    let diameter = last(1) * 1e3;
    let mut out = vec![
        (Measure::Length, last(0) * 1e3),
        (Measure::Radius, 0.5 * diameter),
        (Measure::Diameter, diameter),
    ];
    if b.element.is_some() {
        out.extend([
            (Measure::PlasticStrain, last(2)),
            (Measure::Temperature, last(3)),
        ]);
    }
    Ok(out)
}

/// KEY_MEASURE.svg for each benchmark that has rows: the final shape of each case against its
/// wall time, one series per method, the published values as levels.
pub fn charts(dir: &Path, rows: &[Row]) -> Result<(), OutputError> {
    for b in benchmarks() {
        let file = format!("{}.toml", b.key);
        let runs: Vec<&Row> = rows
            .iter()
            .filter(|r| r.scene.as_deref().is_some_and(|s| s.ends_with(&file)) && r.status == "ok")
            .collect();
        if runs.is_empty() {
            continue;
        }
        error_chart(&b, dir, &runs)?;
        let mut points: Vec<(Method, f64, Vec<(Measure, f64)>)> = Vec::new();
        for r in runs
            .iter()
            .filter(|r| Stepping::of(&r.name) == Stepping::Single)
        {
            points.push((r.method, r.wall_seconds, finals(&b, dir, r)?));
        }
        let (lo, hi) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
        // the meshes a series ran, coarsest first (implicit runs only the coarser ones)
        let meshes = |count: usize| {
            b.meshes[..count.min(3)]
                .iter()
                .map(|nx| format!("{nx}x{}", b.aspect * nx))
                .collect::<Vec<_>>()
                .join(", ")
        };
        for &measure in b.charts {
            let value = |v: &[(Measure, f64)]| {
                v.iter()
                    .find(|(m, _)| *m == measure)
                    .map_or(f64::NAN, |(_, x)| *x)
            };
            let mut series: Vec<Series> = [
                (Method::ExplicitReduced, "one-point"),
                (Method::Explicit, "2x2 B-bar"),
                (Method::Implicit, "implicit average, 2x2 B-bar"),
            ]
            .iter()
            .map(|(method, label)| {
                let points: Vec<(f64, f64)> = points
                    .iter()
                    .filter(|p| p.0 == *method)
                    .map(|p| (p.1, value(&p.2)))
                    .collect();
                Series {
                    label: format!("{label}: {}", meshes(points.len())),
                    points,
                    style: SeriesStyle::LineAndMarkers,
                }
            })
            .filter(|s| !s.points.is_empty())
            .collect();
            series.extend(
                b.references
                    .iter()
                    .filter(|r| r.measure == measure)
                    .map(|r| Series {
                        label: r.label.into(),
                        points: vec![(lo, r.value), (hi, r.value)],
                        style: SeriesStyle::Line,
                    }),
            );
            plot::write(
                &Chart {
                    title: format!("{}: {} against wall time", b.title, measure.label()),
                    x_label: "wall time (s)".into(),
                    y_label: measure.label().into(),
                    series,
                    log_x: true,
                    log_y: false,
                    x_limits: Default::default(),
                    y_limits: Default::default(),
                    notes: Vec::new(),
                },
                &dir.join(format!("{}_{}.svg", b.key, measure.file())),
            )?;
        }
    }
    Ok(())
}

/// One kernel's explicit runs of a benchmark: per run its stepping, elements, wall time
/// and final values.
struct KernelRuns {
    kernel: &'static str,
    runs: Vec<(Stepping, usize, f64, Vec<(Measure, f64)>)>,
}

impl KernelRuns {
    /// The value of `measure` in final values `v`.
    fn value(v: &[(Measure, f64)], measure: Measure) -> f64 {
        v.iter()
            .find(|(m, _)| *m == measure)
            .map_or(f64::NAN, |(_, x)| *x)
    }

    /// The extrapolation of `measure` from the three single-step meshes (None: not three).
    fn extrapolate(&self, measure: Measure) -> Option<crate::sweep::qoi::Extrapolation> {
        // the single-step meshes, finest first (h ~ 1 / sqrt(elements))
        let mut single: Vec<(usize, f64)> = self
            .runs
            .iter()
            .filter(|v| v.0 == Stepping::Single)
            .map(|v| (v.1, Self::value(&v.3, measure)))
            .collect();
        if single.len() != 3 {
            return None;
        }
        single.sort_by(|a, b| b.0.cmp(&a.0));
        let h: [f64; 3] = std::array::from_fn(|i| 1.0 / (single[i].0 as f64).sqrt());
        let f: [f64; 3] = std::array::from_fn(|i| single[i].1);
        Some(crate::sweep::qoi::extrapolate(h, f))
    }

    /// The error of `measure` against `converged` (%, floored at 1e-4 for the log axis)
    /// against the wall time, one series per stepping.
    fn error_series(&self, measure: Measure, converged: f64) -> Vec<Series> {
        Stepping::ALL
            .iter()
            .map(|stepping| Series {
                label: format!("{}, {}", self.kernel, stepping.label()),
                points: self
                    .runs
                    .iter()
                    .filter(|v| v.0 == *stepping)
                    .map(|v| {
                        let error = 100.0 * (Self::value(&v.3, measure) / converged - 1.0);
                        (v.2, error.abs().max(1e-4))
                    })
                    .collect(),
                style: SeriesStyle::LineAndMarkers,
            })
            .filter(|s| !s.points.is_empty())
            .collect()
    }
}

/// KEY_error.svg (and .png): the error of L_f and D_f against the converged value against
/// the wall time, one series per kernel and stepping. The converged value of a measure is
/// the 2x2 kernel's, extrapolated from its three single-step meshes (Celik et al. 2008,
/// `sweep::qoi::extrapolate`; the B-bar element, whose series converges monotonically on
/// both rods), else the one-point kernel's; the notes give each kernel's extrapolation.
/// Nothing is written unless every kernel with rows has its three single-step meshes; a
/// measure no kernel extrapolates has no panel.
fn error_chart(b: &Benchmark, dir: &Path, runs: &[&Row]) -> Result<(), OutputError> {
    let mut kernels = Vec::new();
    for (method, kernel) in [
        (Method::Explicit, "2x2"),
        (Method::ExplicitReduced, "one-point"),
    ] {
        let mut values = Vec::new();
        for r in runs.iter().filter(|r| r.method == method) {
            let stepping = Stepping::of(&r.name);
            values.push((stepping, r.elements, r.wall_seconds, finals(b, dir, r)?));
        }
        if !values.is_empty() {
            kernels.push(KernelRuns {
                kernel,
                runs: values,
            });
        }
    }
    let mut charts = Vec::new();
    for (measure, name) in [(Measure::Length, "L_f"), (Measure::Diameter, "D_f")] {
        let mut notes = Vec::new();
        let mut converged = None;
        for k in &kernels {
            let Some(extrapolation) = k.extrapolate(measure) else {
                return Ok(());
            };
            notes.push(match extrapolation.value {
                Some(v) => format!("{}: {name} extrapolated to {v:.4} mm", k.kernel),
                None => format!("{}: {name} not extrapolated", k.kernel),
            });
            converged = converged.or(extrapolation.value);
        }
        let Some(converged) = converged else {
            continue;
        };
        notes.push(format!("converged {name} taken as {converged:.4} mm"));
        charts.push(Chart {
            title: format!("{}: error of {name}", b.short),
            x_label: "wall time (s)".into(),
            y_label: format!("|{name} - converged| (%)"),
            series: kernels
                .iter()
                .flat_map(|k| k.error_series(measure, converged))
                .collect(),
            log_x: true,
            log_y: true,
            x_limits: Default::default(),
            y_limits: Default::default(),
            notes,
        });
    }
    if charts.is_empty() {
        return Ok(());
    }
    for ext in ["svg", "png"] {
        plot::write_panels(&charts, &dir.join(format!("{}_error.{ext}", b.key)))?;
    }
    Ok(())
}
