#!/usr/bin/env bash
# The restitution of an elastic-perfectly-plastic sphere on a rigid wall against V / V_y
# (models/sphere_restitution.toml; docs/validation.md 4.14): V / V_y = 1, 2, 5, 10, 20, 50, 100
# on three paths (central difference 2x2 B-bar, central difference one-point, Newmark average
# at a fixed step), each run to 1.6 Hertz contact times of its speed, and Thornton's (1997)
# closed form beside them. Writes OUT/restitution.csv: one row per speed with e per path and
# each run's wall seconds, and its chart FIGURES/sphere_restitution.svg (e against V / V_y).
# Usage (from the repository root): bash models/restitution_study.sh [OUT] [N] [FIGURES]
#   N: the sphere's arc steps (default the scene's 40; the mesh keeps its grading 20);
#   FIGURES: default OUT.
set -uo pipefail
if ! command -v impact >/dev/null; then
  impact() { cargo run --release --quiet -- "$@"; }
fi
out=${1:-output/restitution_study}
n=${2:-40}
fig=${3:-$out}
mkdir -p "$out" "$fig"
# the scene's data (keep in step with models/sphere_restitution.toml)
young=210e9 nu=0.3 rho=7850 yield=1e9 radius=5e-3
read -r vy hertz_1 < <(awk -v E="$young" -v nu="$nu" -v rho="$rho" -v Y="$yield" -v R="$radius" 'BEGIN {
  pi = atan2(0, -1); es = E / (1 - nu * nu); m = 4 / 3 * pi * R^3 * rho
  vy = 1.56 * sqrt((1.6 * Y)^5 / (es^4 * rho))            # Thornton 1997
  th = 2.87 * (m^2 / (R * es^2))^0.2                      # Hertz contact time at V = 1
  printf "%.10g %.10g\n", vy, th }')
thornton() { # Thornton 1997, V / V_y = $1 (>= 1)
  awk -v r="$1" 'BEGIN { x = 1 / r
    print sqrt(6 * sqrt(3) / 5) * sqrt(1 - x * x / 6) * (x / (x + 2 * sqrt(6 / 5 - x * x / 5)))^0.25 }'
}
restitution() { # e = -p_y(end) / p_y(0) of the run in $1
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "p_y[all]") c = i; next }
    NR == 2 { p0 = $c } { last = $c } END { printf "%.6f", -last / p0 }' "$1/history.csv"
}
seconds() { sed -n 's/.*"wall_seconds": \([0-9.e+-]*\).*/\1/p' "$1/summary.json"; }
echo "v_over_vy,speed,e_thornton,e_explicit,e_one_point,e_newmark,s_explicit,s_one_point,s_newmark" \
  > "$out/restitution.csv"
for ratio in 1 2 5 10 20 50 100; do
  read -r speed end dt < <(awk -v r="$ratio" -v vy="$vy" -v th="$hertz_1" 'BEGIN {
    v = r * vy; t = th * v^-0.2; printf "%.10g %.10g %.10g\n", v, 1.6 * t, t / 400 }')
  row="$ratio,$speed,$(thornton "$ratio")"
  times=""
  for path in explicit one_point newmark; do
    case $path in
      explicit) set_path=() ;;
      one_point) set_path=(--set analysis.quadrature=reduced) ;;
      newmark) set_path=(--set analysis.integrator=average --set "analysis.dt=$dt") ;;
    esac
    dir=$out/v${ratio}_$path
    impact run models/sphere_restitution.toml --quiet --out "$dir" \
      --set "body.sphere.velocity=[0.0,-$speed]" --set "analysis.end_time=$end" \
      --set "body.sphere.mesh.n=$n" --set output.frame_interval=1 "${set_path[@]}"
    status=$?
    if [ $status -eq 0 ]; then row="$row,$(restitution "$dir")"; else row="$row,"; fi
    times="$times,$(seconds "$dir")"
    echo "V/V_y = $ratio, $path: exit $status"
  done
  echo "$row$times" >> "$out/restitution.csv"
done
column -s, -t "$out/restitution.csv" 2>/dev/null || cat "$out/restitution.csv"
impact plot "$out/restitution.csv" --x v_over_vy --log-x --ymin 0 --ymax 1.05 \
  --y e_thornton --y e_explicit --y e_one_point --y e_newmark \
  --title "Steel sphere on a rigid wall (n = $n): restitution against V / V_y; Thornton 1997 below" \
  --out "$fig/sphere_restitution.svg"
