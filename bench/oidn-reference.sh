#!/usr/bin/env bash
# The real Intel Open Image Denoise (OIDN 2.5.1 from PyPI's pyoidn wheel, CPU device) on the
# same inputs veach denoises: writes the reference outputs tests/denoise.rs compares veach's
# twin with, and times OIDN for BENCHMARKS.md. Nothing here runs in `cargo test`.
#
# Usage:
#   bench/oidn-reference.sh reference IN.exr... --out-dir DIR
#       DIR/STEM.CASE.exr for the cases in bench/oidn_reference.py (balanced, fast, albedo,
#       color, scale05), from EXRs written by `veach render --aov albedo,normal`
#   bench/oidn-reference.sh strip IN.exr... --out-dir DIR
#       DIR/STEM.input.exr: the colour, albedo and normal channels only (compact test inputs)
#   bench/oidn-reference.sh bench --size 512x512 [--repeat 3] [--quality fast|balanced]
#       OIDN's CPU time on a synthetic image of that size (after one warm-up run)
# Environment:
#   VEACH_OIDN_VENV   the Python venv (default ~/.cache/veach-oidn-venv; made when missing with
#                     numpy, cffi, OpenEXR and pyoidn==2.5.1.0)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
venv="${VEACH_OIDN_VENV:-$HOME/.cache/veach-oidn-venv}"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import pyoidn, OpenEXR' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q numpy cffi OpenEXR pyoidn==2.5.1.0
fi
exec "$venv/bin/python" "$here/oidn_reference.py" "$@"
