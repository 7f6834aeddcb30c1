#!/usr/bin/env bash
# Regenerates the charts of docs/validation.md from fresh runs (release build).
# Usage: bash docs/figures/regenerate.sh   (from the repository root)
set -euo pipefail
impact() { cargo run --release --quiet -- "$@"; }
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

impact run models/cantilever_large.toml --quiet --out $out/cantilever_large
impact plot $out/cantilever_large/history.csv --y 'u_x[right]' --y 'u_y[right]' \
  --title 'Elastica cantilever: tip displacement against load factor (k = 2 t)' --out $fig/cantilever_tip.svg

impact run models/hill_cylinder.toml --quiet --out $out/hill_cylinder
impact run models/hill_cylinder.toml --quiet --out $out/hill_cylinder_no_bbar --set body.cylinder.bbar=false
impact plot $out/hill_cylinder/history.csv --y 'u_x[bore]' --reference $out/hill_cylinder_no_bbar/history.csv \
  --title 'Hill cylinder: bore displacement against p / (0.98 p_lim), B-bar and locking plain Q4' \
  --out $fig/hill_bore.svg

# the Erklig impact study (issue #7): both bars, elastic and elastoplastic, five methods
bash models/impact_study.sh $out/impact_study $fig
