#!/usr/bin/env bash
# The grid convergence of the restitution (models/sphere_restitution.toml; docs/validation.md
# 4.14): the sphere's mesh family `refine` = 0, 1, 2 (n = 40, 80, 160 arc steps, the pole step
# halved per level, the scene's grading kept by the family's rule) at V / V_y = 5, 20 and 100,
# on the three paths of models/restitution_study.sh (central difference 2x2 and one-point, both
# at the tight stable step; Newmark average at a four-hundredth of the Hertz time), each run to
# 1.6 Hertz contact times. One `impact sweep` per path and speed (OUT/PATH_vRATIO) measures
# v_end, the centre of mass's final velocity (e V: e = v_end / V with the mesh's own mass),
# with its observed order, Richardson's value and GCI, or, where the levels oscillate, the
# uncertainty U (half their range, Stern et al. 2001): its measures.json, and the closing
# lines printed at the end. OUT/restitution_gci.csv has e per path, speed and level.
# Usage (from the repository root): bash models/restitution_gci.sh [OUT] [LEVELS] [JOBS]
#   LEVELS: the `refine` values (default 0,1,2); JOBS: sweeps at once (default: one per
#   core), each running its levels in turn. The n = 160 cases take 1 to 5 minutes each
#   on one core, the whole family about 25 CPU minutes.
set -uo pipefail
if ! command -v impact >/dev/null; then
  impact() { cargo run --release --quiet -- "$@"; }
fi
out=${1:-output/restitution_gci}
levels=${2:-0,1,2}
jobs=${3:-0}
mkdir -p "$out"
# the scene's data (keep in step with models/sphere_restitution.toml)
young=210e9 nu=0.3 rho=7850 yield=1e9 radius=5e-3
[ "$jobs" -gt 0 ] 2>/dev/null || jobs=$(nproc 2>/dev/null || echo 2)
# one sweep per path and speed (its series: the levels), at most JOBS at once
running=0
declare -A speeds
for ratio in 5 20 100; do
  read -r speed end dt < <(awk -v E="$young" -v nu="$nu" -v rho="$rho" -v Y="$yield" -v R="$radius" -v r="$ratio" 'BEGIN {
    pi = atan2(0, -1); es = E / (1 - nu * nu); m = 4 / 3 * pi * R^3 * rho
    vy = 1.56 * sqrt((1.6 * Y)^5 / (es^4 * rho))            # Thornton 1997
    th = 2.87 * (m^2 / (R * es^2))^0.2                      # Hertz contact time at V = 1
    v = r * vy; t = th * v^-0.2; printf "%.10g %.10g %.10g\n", v, 1.6 * t, t / 400 }')
  speeds[$ratio]=$speed
  for path in explicit one_point newmark; do
    case $path in
      explicit) set_path=(--set analysis.stable_step=tight) ;;
      one_point) set_path=(--set analysis.stable_step=tight --set analysis.quadrature=reduced) ;;
      newmark) set_path=(--set analysis.integrator=average --set "analysis.dt=$dt") ;;
    esac
    impact sweep models/sphere_restitution.toml --vary "body.sphere.mesh.refine=$levels" \
      --set "body.sphere.velocity=[0.0,-$speed]" --set "analysis.end_time=$end" \
      --set output.frame_interval=1 --measure "v_end=final(mass_mean_v_y[all])" --jobs 1 \
      "${set_path[@]}" --out "$out/${path}_v$ratio" > "$out/${path}_v$ratio.log" 2>&1 &
    running=$((running + 1))
    if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
  done
done
wait
echo "path,v_over_vy,refine,e,wall_seconds" > "$out/restitution_gci.csv"
for ratio in 5 20 100; do
  for path in explicit one_point newmark; do
    dir=$out/${path}_v$ratio
    awk -F, -v path="$path" -v ratio="$ratio" -v speed="${speeds[$ratio]}" '
      NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
      { printf "%s,%s,%s,%.6f,%s\n", path, ratio, $col["body.sphere.mesh.refine"],
          $col["v_end"] / speed, $col["wall_seconds"] }' "$dir/sweep.csv" >> "$out/restitution_gci.csv"
    grep -h "^  v_end\|^  note: v_end" "$dir.log" | sed "s/^/$path V\/V_y = $ratio: /"
  done
done
column -s, -t "$out/restitution_gci.csv" 2>/dev/null || cat "$out/restitution_gci.csv"
