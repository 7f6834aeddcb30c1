#!/usr/bin/env bash
# Regenerates the charts of docs/validation.md from fresh runs (release build).
# Usage: bash docs/figures/regenerate.sh   (from the repository root)
set -euo pipefail
# `impact` from the PATH (cargo install --path .); else built and run from the repository
if ! command -v impact >/dev/null; then
  impact() { cargo run --release --quiet -- "$@"; }
fi
out=output/figures
fig=docs/figures

impact run models/two_bars.toml --quiet --out $out/two_bars
impact run models/two_bars.toml --quiet --out $out/two_bars_no_conditions \
  --set contact.bars.impact_conditions=false --set contact.bars.release_conditions=false
impact plot $out/two_bars/history.csv --y 'contact_force[bars]' \
  --reference $out/two_bars_no_conditions/history.csv \
  --title 'Two bars: contact force (exact 0.05 until t = 0.2), with and without impact/release conditions' \
  --out $fig/two_bars_force.svg
impact plot $out/two_bars/history.csv --y 'v_x[bar1.all]' --y 'v_x[bar2.all]' \
  --title 'Two bars: mean velocities (exact: 0.1 -> 0 and 0 -> 0.1)' --out $fig/two_bars_velocity.svg

impact run models/sphere_wall.toml --quiet --out $out/sphere_wall
impact plot $out/sphere_wall/history.csv --y 'contact_force[wall]' \
  --title 'Sphere on a wall, V = 0.8: contact force (Hertz peak 60.2, duration 0.256)' --out $fig/sphere_wall_force.svg

# the contact pressure along the interface at the peak force, against Hertz (validation 4.13)
impact run models/sphere_wall.toml --quiet --out $out/sphere_wall_frames --set output.frame_every=1
peak=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "contact_force[wall]") c = i; next }
  $c > best { best = $c; t = $1 } END { print t }' $out/sphere_wall_frames/history.csv)
frame=$(grep -F "timestep=\"$peak\"" $out/sphere_wall_frames/sphere_wall.pvd | sed 's/.*file="\([^"]*\)".*/\1/')
impact plot $out/sphere_wall_frames/$frame --x x --y contact_pressure --where contact_status --ymin 0 \
  --title "Sphere on a wall at its peak force 62.34 (t = $peak): contact pressure; Hertz p0 83.5, a 0.597" \
  --out $fig/sphere_wall_pressure.svg

impact run models/cantilever_large.toml --quiet --out $out/cantilever_large
impact plot $out/cantilever_large/history.csv --y 'u_x[right]' --y 'u_y[right]' \
  --title 'Elastica cantilever: tip displacement against load factor (k = 2 t)' --out $fig/cantilever_tip.svg

impact run models/hill_cylinder.toml --quiet --out $out/hill_cylinder
impact run models/hill_cylinder.toml --quiet --out $out/hill_cylinder_no_bbar --set body.cylinder.bbar=false
impact plot $out/hill_cylinder/history.csv --y 'u_x[bore]' --reference $out/hill_cylinder_no_bbar/history.csv \
  --title 'Hill cylinder: bore displacement against p / (0.98 p_lim), B-bar and locking plain Q4' \
  --out $fig/hill_bore.svg

# the impact study of Erklig et al. (2010): both bars, elastic and elastoplastic, five methods
bash models/impact_study.sh $out/impact_study $fig

# Sweeps: convergence, speed against accuracy, stability maps.
# Each writes DIR/sweep.csv and charts; the docs' copies are taken from there. A sweep skips
# the cases its folder already holds, so the folders go first: the charts must come from
# this build's runs, not from an earlier one's.
rm -rf "$out"/sweep_*
sweep() { impact sweep "$@" --quiet; }
copy() { for ext in png svg; do cp "$1.$ext" "$fig/$2.$ext"; done; }
refine_bars='body.bar1.mesh.n,body.bar2.mesh.n,analysis.dt=14,14,0.005;28,28,0.0025;56,56,0.00125;112,112,0.000625;224,224,0.0003125'
sweep models/two_bars.toml --vary "$refine_bars" --out $out/sweep_two_bars_courant
copy $out/sweep_two_bars_courant/error_vs_dt sweep_two_bars_courant_dt
sweep models/two_bars.toml --set body.bar1.mesh.n=56 --set body.bar2.mesh.n=56 \
  --vary 'analysis.dt=0.005,0.0025,0.00125,0.000625,0.0003125' --out $out/sweep_two_bars_dt
copy $out/sweep_two_bars_dt/error_vs_dt sweep_two_bars_dt
sweep models/bar_wall.toml --vary 'body.bar.mesh.n,analysis.dt=14,0.005;28,0.0025;56,0.00125;112,0.000625;224,0.0003125' \
  --out $out/sweep_bar_wall_courant
copy $out/sweep_bar_wall_courant/error_vs_h sweep_bar_wall_courant_h
methods='analysis.integrator,analysis.allow_unstable,analysis.mass=central_difference,true,lumped;average,false,consistent;hu,false,consistent;houbolt,false,consistent;wilson,false,consistent'
sweep models/two_bars.toml --vary "$methods" --vary "$refine_bars" \
  --out $out/sweep_two_bars_methods
copy $out/sweep_two_bars_methods/error_vs_cpu sweep_two_bars_speed
copy $out/sweep_two_bars_methods/error_vs_cpu_converged sweep_two_bars_speed_converged
# dt_crit of bar_wall and two_bars: h / c = 1/140 (impact check)
ratios=$(python3 -c "print(','.join(repr(r / 140) for r in (0.5, 0.9, 0.95, 1.05, 2, 10)))")
sweep models/bar_wall.toml --vary "$methods" --vary "analysis.dt=$ratios" --out $out/sweep_bar_wall_stability
copy $out/sweep_bar_wall_stability/stability_map sweep_bar_wall_stability
sweep models/two_bars.toml --vary "$methods" --vary "analysis.dt=$ratios" --out $out/sweep_two_bars_stability
copy $out/sweep_two_bars_stability/stability_map sweep_two_bars_stability
sweep models/sphere_wall.toml --vary 'analysis.integrator=average,hu,houbolt,wilson' \
  --vary 'analysis.dt=0.02,0.01,0.005,0.0025' --out $out/sweep_sphere_wall_methods
copy $out/sweep_sphere_wall_methods/error_vs_cpu sweep_sphere_wall_speed
copy $out/sweep_sphere_wall_methods/error_vs_cpu_converged sweep_sphere_wall_speed_converged

# The Johnson-Cook Taylor rod's mesh study (validation 10.2): four meshes, both quadratures,
# L_f and D_f from the shape probes, Richardson with the GCI; about three minutes on 2 cores
sweep models/taylor_jc.toml --vary 'body.rod.mesh.nx,body.rod.mesh.ny=5,50;10,100;15,150;20,200' \
  --vary 'analysis.quadrature=full,reduced' \
  --measure 'L_f=extent_y[all]' --measure 'D_f=extent_x[all]' --out $out/sweep_taylor_jc_mesh
for m in L_f D_f; do
  copy $out/sweep_taylor_jc_mesh/measure_$m sweep_taylor_jc_$m
  copy $out/sweep_taylor_jc_mesh/error_vs_cpu_$m sweep_taylor_jc_${m}_speed
done

# The implicit step: fixed dt against dt = "auto" at a sweep of tolerances (validation
# 10.3a). taylor_jc with the lumped mass, scored against its explicit 2x2 run (the same
# semi-discretization: L_f, D_f, T, eps_p of `impact run models/taylor_jc.toml`); sphere_wall
# against Hertz (peak force 60.2) and 2 m V (the impulse of an elastic rebound, 8.37758).
# About a minute on 2 cores.
jc='--set analysis.integrator=average --set analysis.mass=lumped
  --measure L_f=extent_y[all] --measure D_f=extent_x[all]
  --measure T=temperature[face_centre] --measure eps_p=eq_plastic_strain[face_centre]
  --reference L_f=0.026531158 --reference D_f=0.011147658 --reference T=589.845
  --reference eps_p=1.80725'
# shellcheck disable=SC2086
sweep models/taylor_jc.toml --vary 'analysis.dt=2e-7,1e-7,5e-8,2.5e-8' $jc \
  --out $out/sweep_taylor_jc_fixed
# shellcheck disable=SC2086
sweep models/taylor_jc.toml --set analysis.dt=auto \
  --vary 'analysis.error_tolerance=3e-2,1e-2,3e-3,1e-3,3e-4' $jc --out $out/sweep_taylor_jc_tolerance
hz='--measure peak=max(contact_force[wall]) --measure impulse=integral(contact_force[wall])
  --reference peak=60.2 --reference impulse=8.37758'
# shellcheck disable=SC2086
sweep models/sphere_wall.toml --vary 'analysis.dt=0.02,0.01,0.005,0.0025' $hz \
  --out $out/sweep_sphere_wall_fixed
# shellcheck disable=SC2086
sweep models/sphere_wall.toml --set analysis.dt=auto \
  --vary 'analysis.error_tolerance=1e-1,3e-2,1e-2,3e-3,1e-3' $hz --out $out/sweep_sphere_wall_tolerance
for s in fixed tolerance; do
  for m in D_f T; do copy $out/sweep_taylor_jc_$s/error_vs_cpu_$m sweep_taylor_jc_${s}_$m; done
  for m in peak impulse; do copy $out/sweep_sphere_wall_$s/error_vs_cpu_$m sweep_sphere_wall_${s}_$m; done
done

# The Taylor rods (aluminium, Johnson-Cook steel): three meshes, one-point and 2x2 explicit,
# implicit Newmark on the two coarser Johnson-Cook meshes; about four minutes
# one thread: the single-step, subcycled and mass-scaled rows compared per core (the 4000-element
# rods would run their single step on two threads, subcycled ones on one)
RAYON_NUM_THREADS=1 impact bench --case taylor_ --out $out/bench_taylor
cp $out/bench_taylor/taylor_*.svg $out/bench_taylor/taylor_*_error.png $fig/
cp $out/bench_taylor/bench.json $fig/taylor_bench.json

# The mass scaling study (validation 10.6): the Taylor rods at 20 x 120 and 20 x 200, one-point,
# without scaling and at two targets each, three repetitions; about three minutes
IMPACT_STUDY_OUT=$out/mass_scaling_study cargo test --release --quiet --test mass_scaling -- \
  --ignored mass_scaling_taylor_study --nocapture
copy $out/mass_scaling_study/mass_scaling_taylor mass_scaling_taylor
cp $out/mass_scaling_study/mass_scaling_taylor.json $fig/

# the restitution of an elastic-perfectly-plastic sphere against V / V_y (validation 4.14)
bash models/restitution_study.sh $out/restitution_study 40 $fig

# the restitution on the sphere's mesh family (validation 4.14): the table holds the runs of
# models/restitution_gci.sh (n = 40, 80, 160) and of `refine = 3` (n = 320), hours on two cores;
# the chart is drawn from it
impact plot $fig/sphere_restitution_family.csv --x n --log-x \
  --y explicit_20 --y one_point_20 --y newmark_20 --y explicit_100 --y one_point_100 --y newmark_100 \
  --title 'Restitution e on the mesh family: 20 V_y (upper), 100 V_y (lower)' \
  --out $fig/sphere_restitution_family.svg

# ALE steps on the Taylor rods and the copper rod at 400 m/s (validation 11): the tables hold
# the runs of `impact run` with and without `analysis.ale = {}` at 5, 10 and 20 elements across
# (the aluminium rod) and the copper rod's `impact sweep` over the same levels; the charts are
# drawn from them
impact plot $fig/ale_taylor_aluminum.csv --x nx --log-x \
  --y D_f_lagrangian_one_point --y D_f_ale_one_point --y D_f_lagrangian_2x2 --y D_f_ale_2x2 \
  --title 'Aluminium Taylor rod: impact-face diameter (mm) against elements across' \
  --out $fig/ale_taylor_aluminum.svg
impact plot $fig/ale_copper.csv --x nx --log-x --y L_f_2x2 --y L_f_one_point \
  --title 'Copper rod at 400 m/s with ALE: final length L_f (mm) against elements across' \
  --out $fig/ale_copper_length.svg
impact plot $fig/ale_copper.csv --x nx --log-x --y D_f_2x2 --y D_f_one_point \
  --title 'Copper rod at 400 m/s with ALE: face diameter D_f (mm) against elements across' \
  --out $fig/ale_copper_diameter.svg
