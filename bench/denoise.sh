#!/usr/bin/env bash
# The denoiser measured for BENCHMARKS.md, in one run on this machine:
#  1. time: veach's CPU twin and WGSL passes (`veach denoise --backend cpu|gpu`) against Open
#     Image Denoise 2.5.1's CPU device (pyoidn) at 512x512 and 1920x1080, both networks;
#  2. what denoising is worth: RMSE (values clamped to [0, 1], what a PNG shows) against the
#     shared Mitsuba reference of the Cornell box (256x256, depth 8) of renders at 1..1024 spp,
#     noisy and denoised.
# Usage: bench/denoise.sh [--repeat N] [--skip-gpu] [--skip-time] [--skip-error]
# Environment: VEACH (binary; default target/release/veach), VEACH_OIDN_VENV (see oidn-reference.sh).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
veach="${VEACH:-$repo/target/release/veach}"
repeat=3; gpu=1; time_it=1; error_it=1
while [ $# -gt 0 ]; do
    case "$1" in
        --repeat) repeat="$2"; shift 2 ;;
        --skip-gpu) gpu=0; shift ;;
        --skip-time) time_it=0; shift ;;
        --skip-error) error_it=0; shift ;;
        *) echo "unknown option $1" >&2; exit 2 ;;
    esac
done
[ -x "$veach" ] || (cd "$repo" && cargo build --release)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
secs() { python3 -c "import json,sys; print('%.3f' % json.load(open(sys.argv[1]))['denoise_seconds'])" "$1"; }
if [ "$time_it" = 1 ]; then
    echo "== denoise time (min of $repeat runs after one warm-up; seconds)"
    for size in 512x512 1920x1080; do
        w=${size%x*}; h=${size#*x}
        "$veach" render "$repo/assets/cornell-box.gltf" -o "$tmp/in.exr" --width "$w" --height "$h" --spp 1 \
            --aov albedo,normal --backend cpu 2>/dev/null
        for quality in fast balanced; do
            engines="cpu"; [ "$gpu" = 1 ] && engines="cpu gpu"
            for engine in $engines; do
                best=""
                for k in $(seq 0 "$repeat"); do
                    "$veach" denoise "$tmp/in.exr" -o "$tmp/out.exr" --backend "$engine" --denoise-quality "$quality" \
                        --stats-json "$tmp/s.json" 2>/dev/null
                    t=$(secs "$tmp/s.json")
                    [ "$k" = 0 ] && continue
                    best=$(python3 -c "print(min(float('$t'), float('${best:-1e9}')))")
                done
                echo "veach $engine $quality $size: $best"
            done
            "$here/oidn-reference.sh" bench --size "$size" --repeat "$repeat" --quality "$quality"
        done
    done
fi
if [ "$error_it" = 1 ]; then
    ref="$repo/../shared/scenes/cbox_ref_d8.exr"
    [ -f "$ref" ] || { echo "no $ref: skipping the error table"; exit 0; }
    echo "== RMSE (clamped) against Mitsuba's Cornell box, 256x256, depth 8, CPU engine"
    for spp in 1 2 4 8 16 32 64 128 256 1024; do
        "$veach" render "$repo/assets/cornell-box.gltf" -o "$tmp/cb$spp.exr" --width 256 --height 256 --spp "$spp" \
            --seed 1 --denoise --backend cpu --stats-json "$tmp/cb$spp.json" 2>/dev/null
    done
    "${VEACH_OIDN_VENV:-$HOME/.cache/veach-oidn-venv}/bin/python" - "$tmp" "$ref" <<'PY'
import json, sys
import numpy as np, OpenEXR
tmp, ref = sys.argv[1], sys.argv[2]
def rd(p, names):
    with OpenEXR.File(p, separate_channels=True) as f:
        ch = f.channels()
        return np.stack([ch[n].pixels.astype(np.float64) for n in names], -1)
R = np.clip(rd(ref, "RGB"), 0, 1)
rmse = lambda a: float(np.sqrt(np.mean((np.clip(a, 0, 1) - R) ** 2)))
print("spp  render_s  noisy     denoised  denoise_s")
for spp in [1, 2, 4, 8, 16, 32, 64, 128, 256, 1024]:
    p = f"{tmp}/cb{spp}.exr"
    s = json.load(open(f"{tmp}/cb{spp}.json"))
    n = rmse(rd(p, "RGB")); d = rmse(rd(p, ["denoised.R", "denoised.G", "denoised.B"]))
    print(f"{spp:<5}{s['seconds_render']:<10.2f}{n:<10.4f}{d:<10.4f}{s['denoise_seconds']:.2f}")
PY
fi
