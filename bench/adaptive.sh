#!/usr/bin/env bash
# Uniform vs adaptive sampling (--noise-threshold) at equal time: the error against the
# independent references after 1, 4 and 16 s of render time on the default backend.
#
# Error is the RMSE of values clamped to [0, 1] (what a tone-mapped image shows). Scenes and
# references: the Cornell box (depth 8) and the Veach MIS scene (depth 2) at 256x256 against
# the shared Mitsuba 3 renders; the glass Cornell box (depth 8) at 64x64 against
# tests/data/cbox_glass_64.exr (Mitsuba 3, 32768 spp).
#
# With --mitsuba, Mitsuba 3 llvm renders the same scenes (bench/compare-mitsuba.sh --equal-time,
# which installs it) and the table gains its error at the same times and veach / Mitsuba.
#
# Usage: bench/adaptive.sh [--threshold T] [--times "1 4 16"] [--backend auto|cpu|gpu] [--mitsuba]
# Environment: VEACH (default target/release/veach), SHARED (default ../shared).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
veach=${VEACH:-$repo/target/release/veach}
shared=${SHARED:-$repo/../shared}
threshold=0.01
times="1 4 16"
backend=auto
mitsuba=0
while [ $# -gt 0 ]; do
  case "$1" in
    --threshold) threshold=$2; shift 2 ;;
    --times) times=$2; shift 2 ;;
    --backend) backend=$2; shift 2 ;;
    --mitsuba) mitsuba=1; shift ;;
    *) echo "adaptive.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# name scene size depth reference
scenes=(
  "cbox $repo/assets/cornell-box.gltf 256 8 $shared/scenes/cbox_ref_d8.exr"
  "glass $repo/assets/cornell-glass.gltf 64 8 $repo/tests/data/cbox_glass_64.exr"
  "veach $repo/assets/veach-mis.gltf 256 2 $shared/scenes/veach_ref.exr"
)
: > "$out/mitsuba.txt"
if [ "$mitsuba" = 1 ]; then
  "$here/compare-mitsuba.sh" --scenes "$shared/scenes" --equal-time "$times" > "$out/mitsuba.txt"
fi
printf "%-6s %5s  %-9s %9s %9s %10s %9s %9s %8s\n" scene secs mode mean_spp max_spp converged rmse01 mitsuba ratio
for row in "${scenes[@]}"; do
  read -r name scene size depth ref <<<"$row"
  for t in $times; do
    for mode in uniform adaptive; do
      extra=()
      [ "$mode" = adaptive ] && extra=(--noise-threshold "$threshold")
      "$veach" render "$scene" -o "$out/i.exr" --width "$size" --height "$size" --max-depth "$depth" \
        --spp 1000000 --time "$t" --backend "$backend" --reference "$ref" --stats-json "$out/s.json" \
        "${extra[@]}" 2>/dev/null
      python3 - "$out/s.json" "$name" "$t" "$mode" "$out/mitsuba.txt" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
c = s["convergence"][-1]
conv = s["converged_fraction"]
name, t = sys.argv[2], sys.argv[3]
m = {(l.split()[0], float(l.split()[1])): float(l.split()[2]) for l in open(sys.argv[5]) if len(l.split()) == 3}
mi = m.get((name, float(t)))
mine = c["rmse_clamped"]
print("%-6s %5s  %-9s %9.1f %9d %10s %9.5f %9s %8s" % (name, t, sys.argv[4], s["mean_spp"], s["spp"],
      "-" if conv is None else "%.3f" % conv, mine, "-" if mi is None else "%.5f" % mi,
      "-" if not mi else "%.2f" % (mine / mi)))
PY
    done
  done
done
