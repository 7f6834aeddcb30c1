//! What an impact user looks for in the frames: the rigid wall beside the bodies, the contact
//! pressure along the interface, point values of what the cells carry (smooth contours) and the
//! points' bodies. The frames are read back with the project's reader of its own appended-raw
//! files (vtkio 0.7 cannot read raw appended data: CRATES.md).

mod common;

use impact::output::vtu::{FrameData, Section, read_frame};
use std::f64::consts::PI;
use std::path::Path;

/// The frame of `dir`'s series at `time` (its .pvd entry closest to it) and that entry's time.
fn frame_at(dir: &Path, name: &str, time: f64) -> (f64, FrameData) {
    let entries = impact::output::vtk::read_pvd(&dir.join(format!("{name}.pvd"))).unwrap();
    let (t, path) = entries
        .iter()
        .min_by(|a, b| (a.0 - time).abs().total_cmp(&(b.0 - time).abs()))
        .unwrap();
    (*t, read_frame(path).unwrap())
}

/// (x, y) of the frame's points.
fn points(frame: &FrameData) -> Vec<[f64; 2]> {
    let (_, v) = frame.floats(Section::Points, "Points").unwrap();
    v.chunks_exact(3).map(|c| [c[0], c[1]]).collect()
}

fn point_array(frame: &FrameData, name: &str) -> Vec<f64> {
    frame
        .floats(Section::PointData, name)
        .unwrap_or_else(|| panic!("no point array `{name}`"))
        .1
        .to_vec()
}

/// The history row at `time`: (the column `column`).
fn history_at(dir: &Path, column: &str, time: f64) -> f64 {
    let times = common::column(dir, "time");
    let k = times
        .iter()
        .position(|t| (t - time).abs() <= 1e-12 * time.abs().max(1e-300))
        .unwrap_or_else(|| panic!("no history row at t = {time}"));
    common::column(dir, column)[k]
}

/// The integral of a nodal pressure over a surface of revolution given as a chain of nodes
/// (current positions): sum_i p_i A_i, A_i = sum over its edges 2 pi L (2 r_i + r_j) / 6,
/// the integral of the node's hat function times 2 pi r (the surface's trapezoidal measure,
/// computed here from the frame's points alone).
fn ring_integral(chain: &[usize], x: &[[f64; 2]], p: &[f64]) -> f64 {
    let mut total = 0.0;
    for w in chain.windows(2) {
        let (i, j) = (w[0], w[1]);
        let length = (x[j][0] - x[i][0]).hypot(x[j][1] - x[i][1]);
        let (ri, rj) = (x[i][0].max(0.0), x[j][0].max(0.0));
        total += p[i] * 2.0 * PI * length * (2.0 * ri + rj) / 6.0;
        total += p[j] * 2.0 * PI * length * (2.0 * rj + ri) / 6.0;
    }
    total
}

/// Goal: the elastic sphere on the rigid wall (models/sphere_wall.toml, Hughes et al. 1975)
/// shows the wall and the contact pressure of Hertz. Setup: the scene with a frame every
/// step; the frame at the peak of the history's contact force.
/// References: the scene's wall, [20, 0] -> [-20, 0], one segment; the pressure's integral
/// over the sphere's arc equals the history's force (the same multipliers, so to round-off:
/// 1e-9); Hertz's distribution p0 sqrt(1 - (r/a)^2) for the history's force F, a =
/// (3 F R / (4 E*))^(1/3), E* = E / (1 - nu^2) against a rigid plane, p0 = 3 F / (2 pi a^2),
/// within 5 % over r < 0.8 a (the band: 30 nodes across the contact at 0.02 spacing,
/// and the dynamic sphere is not quite Hertz's static one; measured within 4.0 %, the axis
/// node the farthest).
#[test]
fn sphere_on_the_wall_shows_the_wall_and_hertz_pressure() {
    let run = common::run_scene(
        "frame_sphere_wall",
        "sphere_wall",
        &["output.frame_every=1"],
    );
    let dir = &run.dir;
    // the wall, written once beside the series
    let walls = impact::output::vtk::read_pvd(&dir.join("sphere_wall_obstacles.pvd")).unwrap();
    assert_eq!(walls.len(), 1);
    let wall = read_frame(&walls[0].1).unwrap();
    assert_eq!(points(&wall), vec![[20.0, 0.0], [-20.0, 0.0]]);
    assert_eq!(wall.integers("connectivity").unwrap(), [0, 1]);
    assert_eq!(wall.ids(Section::CellData, "obstacle").unwrap(), [0]);

    let times = common::column(dir, "time");
    let forces = common::column(dir, "contact_force[wall]");
    let k = (0..forces.len())
        .max_by(|a, b| forces[*a].total_cmp(&forces[*b]))
        .unwrap();
    let (t, frame) = frame_at(dir, "sphere_wall", times[k]);
    assert_eq!(t, times[k], "a frame every step");
    let force = forces[k];
    let x = points(&frame);
    let p = point_array(&frame, "contact_pressure");
    let (_, reference) = frame
        .floats(Section::PointData, "reference_coordinates")
        .unwrap();
    // the arc: the nodes 5 from the centre [0, 5] in the reference configuration, by angle
    let mut arc: Vec<(f64, usize)> = reference
        .chunks_exact(3)
        .enumerate()
        .filter(|(_, c)| ((c[0]).hypot(c[1] - 5.0) - 5.0).abs() < 1e-9)
        .map(|(i, c)| ((c[1] - 5.0).atan2(c[0]), i))
        .collect();
    arc.sort_by(|a, b| a.0.total_cmp(&b.0));
    let chain: Vec<usize> = arc.iter().map(|(_, i)| *i).collect();
    let integral = ring_integral(&chain, &x, &p);
    assert!(
        ((integral - force) / force).abs() < 1e-9,
        "integral {integral} against {force}"
    );

    let e_star = 1000.0 / (1.0 - 0.3 * 0.3);
    let a = (3.0 * force * 5.0 / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * force / (2.0 * PI * a * a);
    let mut checked = 0;
    for &i in &chain {
        let r = x[i][0];
        if r < 0.8 * a && x[i][1] < 0.1 {
            let hertz = p0 * (1.0 - (r / a).powi(2)).sqrt();
            assert!(
                (p[i] / hertz - 1.0).abs() < 0.05,
                "r = {r}: p {} against Hertz {hertz}",
                p[i]
            );
            checked += 1;
        }
    }
    assert!(checked >= 10, "{checked} nodes inside 0.8 a = {}", 0.8 * a);
}

/// Goal: two deformable bodies (models/rod_on_rod.toml, one pass of mortar, explicit; the
/// balanced default's master face integrates to 0.56 % of its slave face's, the pressures of
/// two node-to-segment passes recovered on half edges): the contact
/// pressure on the slave face integrates to the history's force, the master face carries
/// the same load, the point plastic strain lies within the cells around each point, and each
/// point names its body. Setup: the scene to 10 us (the rods pressed together), frames every
/// 100 steps. References: the history's force (the same multipliers: 1e-9); the master's
/// integral, the reaction of the same force (Newton's third law; its normals are the
/// master's, not the mortar's mean normal: within 0.1 %, measured 8e-5); the cells around a
/// point (their
/// mean lies between their least and largest value); the body of the cells around a point.
#[test]
fn two_rods_show_their_contact_pressure_plastic_strain_and_bodies() {
    let run = common::run_scene(
        "frame_rod_on_rod",
        "rod_on_rod",
        &[
            "analysis.end_time=10.0e-6",
            "output.frame_every=100",
            "contact.faces.roles=as_written",
        ],
    );
    let dir = &run.dir;
    assert!(
        !dir.join("rod_on_rod_obstacles.pvd").exists(),
        "no obstacle"
    );
    let entries = impact::output::vtk::read_pvd(&dir.join("rod_on_rod.pvd")).unwrap();
    let (t, path) = entries.last().unwrap();
    let frame = read_frame(path).unwrap();
    let force = history_at(dir, "contact_force[faces]", *t);
    assert!(force > 0.0, "pressed together at {t}");
    let x = points(&frame);
    let p = point_array(&frame, "contact_pressure");
    let (_, reference) = frame
        .floats(Section::PointData, "reference_coordinates")
        .unwrap();
    let face = |y: f64| -> Vec<usize> {
        let mut nodes: Vec<(f64, usize)> = reference
            .chunks_exact(3)
            .enumerate()
            .filter(|(_, c)| (c[1] - y).abs() < 1e-12)
            .map(|(i, c)| (c[0], i))
            .collect();
        nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
        nodes.into_iter().map(|(_, i)| i).collect()
    };
    let bodies = frame.ids(Section::PointData, "body").unwrap();
    // both faces start at y = 0: the upper rod's (body 0) is the slave, the lower's the master
    let (slave, master): (Vec<usize>, Vec<usize>) =
        face(0.0).into_iter().partition(|i| bodies[*i] == 0);
    assert_eq!((slave.len(), master.len()), (6, 6));
    let on_slave = ring_integral(&slave, &x, &p);
    assert!(
        ((on_slave - force) / force).abs() < 1e-9,
        "slave {on_slave} against {force}"
    );
    let on_master = ring_integral(&master, &x, &p);
    assert!(
        ((on_master - force) / force).abs() < 1e-3,
        "master {on_master} against {force}"
    );

    let nodal = point_array(&frame, "nodal_eq_plastic_strain");
    let (_, cells) = frame
        .floats(Section::CellData, "eq_plastic_strain")
        .unwrap();
    let cell_bodies = frame.ids(Section::CellData, "body").unwrap();
    let connectivity = frame.integers("connectivity").unwrap();
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); x.len()];
    for (c, quad) in connectivity.chunks_exact(4).enumerate() {
        for &n in quad {
            around[n as usize].push(c);
        }
    }
    assert!(cells.iter().any(|e| *e > 0.01), "the rods yield");
    for (n, cells_around) in around.iter().enumerate() {
        let (lo, hi) = cells_around
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(cells[*c]), hi.max(cells[*c]))
            });
        assert!(
            nodal[n] >= lo - 1e-15 && nodal[n] <= hi + 1e-15,
            "point {n}: {} outside [{lo}, {hi}]",
            nodal[n]
        );
        assert!(cells_around.iter().all(|c| cell_bodies[*c] == bodies[n]));
    }
}

/// Goal: the first frame shows the initial gaps (it showed 0 everywhere). Setup:
/// models/rod_on_plate.toml to 1 us, frames every 0.5 us (a balanced pair: the rod's face and
/// the plate's top are each the other's slaves). Reference: the scene places the rod's bottom
/// (r <= 4 mm) 1 um above the plate's top: the rod's 9 face nodes and the plate's 9 top nodes
/// under it have the gap 1e-6 (to round-off of coordinates near 1e-2); the plate's 32 top
/// nodes beyond the rod's rim (r = 4.5 ... 20 mm) their distance from its corner,
/// sqrt((r - 4 mm)^2 + (1 um)^2), within the balanced pair's search distance (twice the
/// longest face element, 2 x 0.5 mm: the node at r = 4.5 mm; the node at 5 mm lies 1e-12 m
/// beyond it); every other point 0 (no master in reach).
#[test]
fn the_first_frame_shows_the_initial_gaps() {
    let run = common::run_scene(
        "frame_initial_gap",
        "rod_on_plate",
        &["analysis.end_time=1.0e-6", "output.frame_interval=0.5e-6"],
    );
    let (t, frame) = frame_at(&run.dir, "rod_on_plate", 0.0);
    assert_eq!(t, 0.0);
    let gap = point_array(&frame, "gap");
    let open: Vec<f64> = gap.iter().copied().filter(|g| *g != 0.0).collect();
    assert_eq!(open.len(), 19, "{open:?}");
    let facing = open.iter().filter(|g| (*g - 1e-6).abs() < 1e-15).count();
    assert_eq!(facing, 18, "{open:?}");
    let mut beyond: Vec<f64> = open
        .into_iter()
        .filter(|g| (g - 1e-6).abs() >= 1e-15)
        .collect();
    beyond.sort_by(f64::total_cmp);
    for (k, g) in beyond.iter().enumerate() {
        let r = 4.5e-3 + 0.5e-3 * k as f64;
        let exact = ((r - 4.0e-3).powi(2) + 1e-12).sqrt();
        assert!((g / exact - 1.0).abs() < 1e-9, "{k}: {g} against {exact}");
    }
}

/// Goal: `impact plot FRAME.vtu` charts a point array along the touching nodes (the contact
/// pressure against the radius), and a column the frame lacks is an input error naming it.
/// Setup: frame 16 of sphere_wall (t = 0.127, its peak force). Reference: the frame's
/// own arrays read back: the rows are the points with contact_status 1, by increasing x.
#[test]
fn a_frame_plots_the_pressure_along_the_interface() {
    let run = common::run_scene("frame_plot", "sphere_wall", &["output.frame_every=1"]);
    let entries = impact::output::vtk::read_pvd(&run.dir.join("sphere_wall.pvd")).unwrap();
    let path = &entries[16].1;
    let frame = read_frame(path).unwrap();
    let status = point_array(&frame, "contact_status");
    let pressure = point_array(&frame, "contact_pressure");
    let x = points(&frame);
    let mut expected: Vec<(f64, f64)> = (0..x.len())
        .filter(|i| status[*i] != 0.0)
        .map(|i| (x[i][0], pressure[i]))
        .collect();
    expected.sort_by(|a, b| a.0.total_cmp(&b.0));
    let columns = impact::output::plot::frame_columns(
        path,
        &["x", "contact_pressure"],
        Some("contact_status"),
    )
    .unwrap();
    let rows: Vec<(f64, f64)> = columns[0].iter().copied().zip(columns[1].clone()).collect();
    assert!(expected.len() >= 10);
    assert_eq!(rows, expected);

    let chart = run.dir.join("pressure.svg");
    let frame_arg = path.to_str().unwrap();
    let args = ["plot", frame_arg, "--x", "x", "--y", "contact_pressure"];
    let ok = common::impact(
        &[
            &args[..],
            &[
                "--where",
                "contact_status",
                "--out",
                chart.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(
        std::fs::read_to_string(&chart)
            .unwrap()
            .contains("contact_pressure")
    );
    let bad = common::impact(&["plot", frame_arg, "--x", "x", "--y", "pressure_of_contact"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no point column `pressure_of_contact`"));
}

/// Goal: frames at listed times cost the explicit run nothing: the steps to each frame are
/// equal (no short step that spikes a column, no alternation of long and short steps that
/// broke the stability of frequent frames), and the frames and the end fall on their times
/// exactly. Setup: models/bar_wall.toml on central difference (lumped mass, dt = "auto")
/// with a frame every 0.01: the bar's stable step is L / (n c) = 10 / (14 * 100) = 0.00714,
/// 0.9 of it 0.00643, so each 0.01 between frames takes two equal steps of 0.005 (before:
/// 0.00643 and 0.00357 alternating, until the energy grew at t = 0.126 and the run stopped).
/// Reference: the steps, by hand; d'Alembert's contact force rho c A v = 0.1 for 2 L / c =
/// 0.2 (the plateau's mean on [0.02, 0.18] within 1 %: the lumped rod's ripple is 3 %,
/// measured -0.13 %); the end at 0.4 exactly.
#[test]
fn frequent_frames_split_the_explicit_steps_equally() {
    let run = common::run_scene(
        "frame_bar_wall",
        "bar_wall",
        &[
            "analysis.integrator=central_difference",
            "analysis.mass=lumped",
            "analysis.dt=auto",
            "output.frame_interval=0.01",
        ],
    );
    assert_eq!(run.summary.status, impact::analysis::Status::Ok);
    let times = common::column(&run.dir, "time");
    let steps = common::column(&run.dir, "dt");
    assert_eq!(*times.last().unwrap(), 0.4);
    assert!(
        steps[1..].iter().all(|h| (h - 0.005).abs() < 1e-12),
        "{steps:?}"
    );
    let plateau = common::window(&run.dir, "contact_force[wall]", 0.02, 0.18);
    assert!((common::mean(&plateau) / 0.1 - 1.0).abs() < 0.01);
    let frames = impact::output::vtk::read_pvd(&run.dir.join("bar_wall.pvd")).unwrap();
    assert_eq!(frames.len(), 41);
    for (k, (t, _)) in frames.iter().enumerate() {
        assert!((t - 0.01 * k as f64).abs() <= 1e-15, "frame {k} at {t}");
    }
}

/// Goal: the same on a continuum with an impact (models/steel_block_wall.toml, a frame every
/// microsecond, about 11 steps apart). Reference: the stable step changes only as the
/// elements deform, by far less than the 0.019 of a step clipped to a frame time (before:
/// steps of 1.7e-9 beside 9.2e-8, the end at 2.9999999999999997e-5): no step below 0.8 of
/// the one before it (a frame interval split in one step more than the last: 10/11 at
/// least, measured 0.857 where the bound fell), every frame at k us, the end at 30 us.
#[test]
fn frames_at_listed_times_leave_no_short_step() {
    let run = common::run_scene("frame_block_wall", "steel_block_wall", &[]);
    let times = common::column(&run.dir, "time");
    let steps = common::column(&run.dir, "dt");
    assert_eq!(*times.last().unwrap(), 30e-6);
    for k in 2..steps.len() {
        assert!(
            steps[k] > 0.8 * steps[k - 1],
            "step {k}: {} after {}",
            steps[k],
            steps[k - 1]
        );
    }
    let frames = impact::output::vtk::read_pvd(&run.dir.join("steel_block_wall.pvd")).unwrap();
    assert_eq!(frames.len(), 31);
    for (k, (t, _)) in frames.iter().enumerate() {
        assert!((t - 1e-6 * k as f64).abs() <= 1e-18, "frame {k} at {t}");
    }
}
