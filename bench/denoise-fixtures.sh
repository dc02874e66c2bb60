#!/usr/bin/env bash
# Makes tests/data/denoise/: small noisy renders by veach (colour, albedo and normal AOVs) and
# what the real Open Image Denoise 2.5.1 (pyoidn, CPU device) makes of them, for
# tests/denoise.rs. Run from anywhere; needs the network once (the venv of oidn-reference.sh).
#
#   bench/denoise-fixtures.sh [OUT_DIR]      (default: tests/data/denoise)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
out="${1:-$repo/tests/data/denoise}"
veach="${VEACH:-$repo/target/release/veach}"
[ -x "$veach" ] || (cd "$repo" && cargo build --release)
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Sizes that are not multiples of 16 (the network pads them), low spp, the CPU engine.
"$veach" render "$repo/assets/cornell-glass.gltf" -o "$tmp/cbox_glass.exr" --width 72 --height 56 --spp 4 \
    --seed 3 --aov albedo,normal --backend cpu
"$veach" render "$repo/assets/veach-mis.gltf" -o "$tmp/veach_mis.exr" --width 64 --height 40 --spp 2 \
    --max-depth 2 --seed 5 --aov albedo,normal --backend cpu
venv="${VEACH_OIDN_VENV:-$HOME/.cache/veach-oidn-venv}"
"$here/oidn-reference.sh" strip "$tmp/cbox_glass.exr" "$tmp/veach_mis.exr" --out-dir "$out"
"$here/oidn-reference.sh" reference "$out/cbox_glass.input.exr" "$out/veach_mis.input.exr" --out-dir "$out"
ls -l "$out"
