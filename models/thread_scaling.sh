#!/usr/bin/env bash
# Thread scaling of the explicit driver (docs/performance.md, "Threads kept awake"): the two
# runs whose speed-ups the performance targets name, each on 1, 2, 4, ... threads up to the
# machine's cores (or MAX_THREADS), frames off, every count run twice in interleaved rounds:
#   taylor_jc        models/taylor_jc.toml, one-point 20 x 200 (4000 elements), to 80 us
#   taylor_aluminum  models/taylor_aluminum.toml, one-point 20 x 120 (2400 elements), to 45 us
# Prints each run's wall seconds (summary.json `wall_seconds`), the faster of the two rounds
# and its speed-up against one thread, and checks that history.csv is the same bits at every
# count (the driver's sums add fixed chunks in a fixed order). One run of each count on one
# thread takes about 25 s and 15 s on the 2-core development machine.
# Usage (from the repository root): bash models/thread_scaling.sh [OUT] [MAX_THREADS]
set -euo pipefail
# `impact` from the PATH (cargo install --path .); else built and run from the repository
if ! command -v impact >/dev/null; then
  cargo build --release --quiet
  impact() { target/release/impact "$@"; }
fi
out=${1:-output/thread_scaling}
max=${2:-$(nproc)}
counts=()
for ((t = 1; t <= max; t *= 2)); do counts+=("$t"); done
if [ "${counts[-1]}" -ne "$max" ]; then counts+=("$max"); fi
mkdir -p "$out"

# name, scene, and the settings of the case
cases=(
  "taylor_jc|models/taylor_jc.toml|--set body.rod.mesh.nx=20 --set body.rod.mesh.ny=200 --set analysis.quadrature=reduced"
  "taylor_aluminum|models/taylor_aluminum.toml|--set body.rod.mesh.nx=20 --set body.rod.mesh.ny=120"
)

wall() { grep -o '"wall_seconds": *[0-9.e+-]*' "$1/summary.json" | sed 's/.*: *//'; }

for round in 1 2; do
  for case in "${cases[@]}"; do
    IFS='|' read -r name scene settings <<<"$case"
    for t in "${counts[@]}"; do
      dir="$out/$name-$t-$round"
      # shellcheck disable=SC2086 # the settings are words
      RAYON_NUM_THREADS=$t impact run "$scene" --quiet --out "$dir" \
        --set output.frame_every=0 $settings
      echo "$name, $t threads, round $round: $(wall "$dir") s"
    done
  done
done

echo
printf '%-16s %8s %10s %10s %10s %9s  %s\n' case threads "round 1" "round 2" best speed-up history
for case in "${cases[@]}"; do
  IFS='|' read -r name _ _ <<<"$case"
  one=
  for t in "${counts[@]}"; do
    a=$(wall "$out/$name-$t-1")
    b=$(wall "$out/$name-$t-2")
    best=$(awk -v a="$a" -v b="$b" 'BEGIN { print (a < b ? a : b) }')
    one=${one:-$best}
    same=same
    for round in 1 2; do
      cmp -s "$out/$name-1-1/history.csv" "$out/$name-$t-$round/history.csv" || same=DIFFERS
    done
    awk -v n="$name" -v t="$t" -v a="$a" -v b="$b" -v best="$best" -v one="$one" -v s="$same" \
      'BEGIN { printf "%-16s %8d %10.2f %10.2f %10.2f %8.2fx  %s\n", n, t, a, b, best, one / best, s }'
  done
done
