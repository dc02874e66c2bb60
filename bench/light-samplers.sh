#!/usr/bin/env bash
# Error of the light samplers (--light-sampler power | tree | ris) at equal spp and at equal
# time, on the Veach MIS scene (depth 2 and 8), the Cornell box (depth 8) and the generated
# many-light scene and glossy hall (`veach bench --write-scenes`), on one backend.
#
# Error is the RMSE of values clamped to [0, 1] (what a tone-mapped image shows) against a
# reference: the shared Mitsuba 3 renders where they fit (Veach depth 2, Cornell depth 8,
# 256x256), else a long veach render with the power sampler (the former sampler, whose
# agreement with Mitsuba is established), made in the same run.
#
# With --regions, the final images' MSE of values clamped to [0, 4] and RMSE clamped to [0, 1]
# over the whole image and by region (glossy: first surface metallic with roughness < 0.5, by
# the albedo AOV of a 1-spp render; diffuse: the rest), by bench/light_regions.py (numpy and
# OpenEXR, from the Mitsuba venv of compare-mitsuba.sh: VEACH_BENCH_VENV).
#
# Usage: bench/light-samplers.sh [--backend cpu|gpu] [--size N] [--spp N] [--regions]
#        [--scene NAME]... (veach-d2 veach-d8 cbox-d8 many-lights glossy-hall; default all)
# Environment: VEACH (default target/release/veach), SHARED (default ../shared).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
veach=${VEACH:-$repo/target/release/veach}
shared=${SHARED:-$repo/../shared}
backend=cpu
size=256
spp=256
regions=0
only=()
while [ $# -gt 0 ]; do
  case "$1" in
    --regions) regions=1; shift ;;
    --scene) only+=("$2"); shift 2 ;;
    --backend) backend=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    *) echo "light-samplers.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$veach" bench --write-scenes "$out" >/dev/null 2>&1

# name scene depth reference (empty: made here)
cases=(
  "veach-d2 $shared/scenes/veach.gltf 2 $shared/scenes/veach_ref.exr"
  "veach-d8 $shared/scenes/veach.gltf 8 -"
  "cbox-d8 $shared/scenes/cbox.gltf 8 $shared/scenes/cbox_ref_d8.exr"
  "many-lights $out/many-lights.gltf 2 -"
  "glossy-hall $out/glossy-hall.gltf 2 -"
)
venv=${VEACH_BENCH_VENV:-$HOME/.cache/veach-bench-venv}
printf '%-12s %-6s %8s %10s %12s %12s\n' scene sampler spp seconds rmse_clamped "Msamples/s"
for c in "${cases[@]}"; do
  read -r name scene depth ref <<<"$c"
  if [ ${#only[@]} -gt 0 ] && [[ ! " ${only[*]} " =~ " $name " ]]; then continue; fi
  if [ "$ref" = "-" ] || [ "$size" != 256 ]; then
    ref="$out/$name-ref.exr"
    "$veach" render "$scene" -o "$ref" --width "$size" --height "$size" --max-depth "$depth" \
      --spp $((spp * 16)) --light-sampler power --backend "$backend" --seed 99 2>/dev/null
  fi
  for sampler in power tree ris; do
    stats="$out/$name-$sampler.json"
    "$veach" render "$scene" -o "$out/$name-$sampler.exr" --width "$size" --height "$size" \
      --max-depth "$depth" --spp "$spp" --light-sampler "$sampler" --backend "$backend" \
      --reference "$ref" --stats-json "$stats" 2>/dev/null
    python3 - "$stats" "$name" "$sampler" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for p in s["convergence"]:
    if p["spp"] >= 4:
        print(f'{sys.argv[2]:<12} {sys.argv[3]:<6} {p["spp"]:>8} {p["seconds"]:>10.3f} {p["rmse_clamped"]:>12.5f} {s["samples_per_second"] / 1e6:>12.3f}')
PY
  done
  if [ "$regions" = 1 ]; then
    "$veach" render "$scene" -o "$out/$name-albedo.exr" --width "$size" --height "$size" --spp 1 \
      --max-depth "$depth" --aov albedo --backend "$backend" 2>/dev/null
    "$venv/bin/python" "$here/light_regions.py" "$ref" "$out/$name-albedo.exr" \
      "$out/$name-power.exr" "$out/$name-tree.exr" "$out/$name-ris.exr"
  fi
done
