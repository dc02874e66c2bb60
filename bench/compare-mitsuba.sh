#!/usr/bin/env bash
# Render the same scenes with veach (gpu and cpu backends) and Mitsuba 3 (llvm_ad_rgb and
# scalar_rgb) in one run, and print samples/s and the ratios
#   veach-gpu / mitsuba-llvm   and   veach-cpu / mitsuba-scalar
# per scene, so that a speed claim against Mitsuba can be checked by anyone on the same machine.
#
# Usage: bench/compare-mitsuba.sh [options]
#   --scenes DIR        scene directory with NAME.json + NAME.gltf (default: ../shared/scenes
#                       relative to the repository root)
#   --scene NAME        a scene to run (repeatable; default: cbox and veach)
#   --size N            image width = height (default 256)
#   --spp N             samples per pixel (default 64)
#   --depth N           max depth in path segments, Mitsuba's max_depth (default 8; 0 = no limit)
#   --seed N            seed for both renderers (default 7)
#   --repeat N          timed runs per renderer and scene; the median is reported (default 1)
#   --mitsuba-rr-depth N  Mitsuba's rr_depth (default 5 = Mitsuba's default; veach starts
#                       Russian roulette after 4 segments, so 4 makes the integrators match)
#   --variants LIST     Mitsuba variants (default llvm_ad_rgb,scalar_rgb; "" = no Mitsuba)
#   --backends LIST     veach backends (default gpu,cpu; "" = no veach)
#   --veach-sampler S   veach's --sampler (default sobol, veach's default; Mitsuba runs its
#                       independent sampler, so "independent" compares equal work per sample)
#   --rmse              write every image as EXR (Mitsuba: mi.util.write_bitmap) and print the
#                       image means and RMSE against mitsuba-llvm and, where one fits the
#                       settings, against the shared reference render; where a reference fits
#                       (cbox at depth 8 or 0, veach at depth 2, 256x256), also the error at
#                       equal time: veach records --reference series, Mitsuba renders 1, 2, 4,
#                       ... spp (each timed warm), and the report interpolates both to the same
#                       times; plots go to OUT_DIR/convergence_SCENE.png (veach plot-convergence)
#   --equal-time TIMES  only Mitsuba llvm's clamped RMSE at these render times (e.g. "1 4 16")
#                       on bench/adaptive.sh's scenes and references (Cornell box d8 256²,
#                       glass Cornell box d8 64², Veach d2 256²), one "scene seconds rmse" line
#                       each; bench/adaptive.sh --mitsuba sets it and prints the ratios
#   --out-dir DIR       where the images and stats go (default: a temp dir, removed unless --rmse)
#   --json FILE         also write all numbers plus machine info (nproc, CPU model, date) as JSON
# Environment:
#   VEACH               veach binary (default: target/release/veach in the repository)
#   VEACH_BENCH_VENV    Python venv for Mitsuba (default: ~/.cache/veach-bench-venv)
#   VEACH_BENCH_MITSUBA Mitsuba version to pin (default 3.9.1, the version of the shared references)
#   DRJIT_LIBLLVM_PATH  libLLVM for the llvm variant (default: the newest libLLVM >= 17 found;
#                       LLVM 15, Debian 12's Mesa LLVM, cannot compile Mitsuba's kernels)
#
# Timing: Mitsuba renders once to warm up (JIT compilation) and then times mi.render plus the
# conversion of the image to numpy (which forces the llvm kernels to finish). veach reports
# samples_per_second from --stats-json (render only, no scene load or BVH build); each veach
# scene and backend is first run once at 16x16, 1 spp, to warm the disk caches.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)

scenes_dir="$repo/../shared/scenes"
scene_list=()
size=256
spp=64
depth=8
seed=7
repeat=1
rr_depth=5
variants="llvm_ad_rgb,scalar_rgb"
backends="gpu,cpu"
veach_sampler=sobol
rmse=0
out_dir=""
json_out=""
equal_time=""

die() { echo "compare-mitsuba: $*" >&2; exit 1; }
need_arg() { [[ $# -ge 2 ]] || die "$1 needs a value"; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenes) need_arg "$@"; scenes_dir=$2; shift 2 ;;
    --scene) need_arg "$@"; scene_list+=("$2"); shift 2 ;;
    --size) need_arg "$@"; size=$2; shift 2 ;;
    --spp) need_arg "$@"; spp=$2; shift 2 ;;
    --depth) need_arg "$@"; depth=$2; shift 2 ;;
    --seed) need_arg "$@"; seed=$2; shift 2 ;;
    --repeat) need_arg "$@"; repeat=$2; shift 2 ;;
    --mitsuba-rr-depth) need_arg "$@"; rr_depth=$2; shift 2 ;;
    --variants) need_arg "$@"; variants=$2; shift 2 ;;
    --backends) need_arg "$@"; backends=$2; shift 2 ;;
    --veach-sampler) need_arg "$@"; veach_sampler=$2; shift 2 ;;
    --rmse) rmse=1; shift ;;
    --equal-time) need_arg "$@"; equal_time=$2; shift 2 ;;
    --out-dir) need_arg "$@"; out_dir=$2; shift 2 ;;
    --json) need_arg "$@"; json_out=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option $1 (see --help)" ;;
  esac
done
for v in size spp depth seed repeat rr_depth; do
  [[ ${!v} =~ ^[0-9]+$ ]] || die "--${v//_/-} must be a non-negative integer, got '${!v}'"
done
(( size > 0 && spp > 0 && repeat > 0 )) || die "--size, --spp and --repeat must be positive"
[[ ${#scene_list[@]} -gt 0 ]] || scene_list=(cbox veach)
[[ -d $scenes_dir ]] || die "scene directory $scenes_dir not found (use --scenes DIR)"
scenes_dir=$(cd "$scenes_dir" && pwd)
for s in "${scene_list[@]}"; do
  [[ -z $variants || -f $scenes_dir/$s.json ]] || die "$scenes_dir/$s.json not found"
  [[ -z $backends || -f $scenes_dir/$s.gltf ]] || die "$scenes_dir/$s.gltf not found"
done
IFS=, read -r -a backend_list <<< "$backends"
for b in "${backend_list[@]}"; do
  [[ $b == gpu || $b == cpu ]] || die "unknown veach backend '$b' (gpu, cpu)"
done
[[ -n $json_out ]] && json_out=$(realpath -m "$json_out")

# ---- veach binary ---------------------------------------------------------------------------
veach_bin=${VEACH:-$repo/target/release/veach}
if [[ ${#backend_list[@]} -gt 0 && ! -x $veach_bin ]]; then
  echo "compare-mitsuba: $veach_bin not found; build it first: cargo build --release (or set VEACH=...)" >&2
  exit 2
fi

# ---- Mitsuba venv -----------------------------------------------------------------------------
venv=${VEACH_BENCH_VENV:-$HOME/.cache/veach-bench-venv}
mitsuba_version=${VEACH_BENCH_MITSUBA:-3.9.1}
py="$venv/bin/python"
# (always: the report and the image statistics run in it too)
if [[ ! -x $py ]]; then
  python3 -m venv "$venv" >/dev/null 2>&1 \
    || die "cannot create a venv at $venv (python3 -m venv failed; on Debian: apt-get install python3-venv)"
fi
have=$("$py" -c 'import mitsuba, numpy; print(mitsuba.__version__)' 2>/dev/null || true)
if [[ $have != "$mitsuba_version" ]]; then
  echo "installing mitsuba==$mitsuba_version and numpy into $venv ..." >&2
  if ! "$py" -m pip install -q "mitsuba==$mitsuba_version" numpy > "$venv/pip.log" 2>&1; then
    die "pip could not install mitsuba==$mitsuba_version into $venv (no network to PyPI?); see $venv/pip.log"
  fi
fi

# ---- LLVM for the llvm variant ----------------------------------------------------------------
# Dr.Jit loads libLLVM at run time. LLVM 15 (Debian 12, used by Mesa) aborts with "Cannot
# select: fminimum" on Mitsuba's path integrator; LLVM >= 17 works (19 tested).
llvm_major() { basename "$1" | sed -E 's/^libLLVM[-.]?(so\.)?([0-9]+).*/\2/'; }
find_llvm() {
  local best="" best_v=0 f v
  for f in /usr/lib/x86_64-linux-gnu/libLLVM* /usr/lib/aarch64-linux-gnu/libLLVM* /usr/lib/llvm-*/lib/libLLVM*.so* /usr/lib64/libLLVM*; do
    [[ -f $f ]] || continue
    v=$(llvm_major "$f")
    [[ $v =~ ^[0-9]+$ ]] || continue
    if (( v > best_v )); then best=$f; best_v=$v; fi
  done
  (( best_v >= 17 )) && echo "$best"
  return 0
}
if [[ ,$variants, == *,llvm* && -z ${DRJIT_LIBLLVM_PATH:-} ]]; then
  lib=$(find_llvm)
  if [[ -z $lib ]] && command -v apt-get >/dev/null && [[ $(id -u) == 0 ]]; then
    echo "installing libllvm19 (Mitsuba's llvm variant needs LLVM >= 17) ..." >&2
    { apt-get install -y -q libllvm19 || { apt-get update -q && apt-get install -y -q libllvm19; }; } >/dev/null 2>&1 || true
    lib=$(find_llvm)
  fi
  [[ -n $lib ]] || die "Mitsuba's llvm_ad_rgb needs libLLVM >= 17 (LLVM 15 cannot compile its kernels): apt-get install libllvm19, set DRJIT_LIBLLVM_PATH, or use --variants scalar_rgb"
  export DRJIT_LIBLLVM_PATH=$lib
fi

if [[ -n $equal_time ]]; then
  "$py" "$here/mitsuba_scenes.py" equal-time --scenes "$scenes_dir" --times "$equal_time" \
    --rr-depth "$rr_depth" --seed "$seed" --cbox-ref "$scenes_dir/cbox_ref_d8.exr" \
    --glass-ref "$repo/tests/data/cbox_glass_64.exr" --veach-ref "$scenes_dir/veach_ref.exr"
  exit 0
fi

# ---- work dir -------------------------------------------------------------------------------
if [[ -n $out_dir ]]; then
  mkdir -p "$out_dir"; out_dir=$(cd "$out_dir" && pwd); keep=1
else
  out_dir=$(mktemp -d /tmp/veach-compare.XXXXXX); keep=$rmse
fi
cleanup() { if [[ $keep == 0 ]]; then rm -rf "$out_dir"; fi; }
trap cleanup EXIT

load=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo 0)
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2- | sed 's/^ //'), load average $load" >&2
if awk -v l="$load" 'BEGIN { exit !(l > 0.5) }'; then
  echo "warning: load average $load: something else is running; the numbers will be low and noisy" >&2
fi
echo "settings: ${size}x${size}, $spp spp, max depth $depth, seed $seed, veach sampler $veach_sampler, $repeat timed run(s); scenes ${scene_list[*]} from $scenes_dir" >&2

# The shared reference render that fits a scene at these settings (as reference_for in
# mitsuba_scenes.py), or nothing.
reference_for() {
  local f=""
  (( size == 256 )) || return 0
  case "$1:$depth" in
    cbox:8) f=cbox_ref_d8.exr ;;
    cbox:0) f=cbox_ref.exr ;;
    veach:2) f=veach_ref.exr ;;
  esac
  [[ -n $f && -f $scenes_dir/$f ]] && echo "$scenes_dir/$f"
  return 0
}

# ---- veach ----------------------------------------------------------------------------------
veach_tsv="$out_dir/veach_runs.tsv"
: > "$veach_tsv"
if [[ ${#backend_list[@]} -gt 0 ]]; then
  echo "veach: $veach_bin ($("$veach_bin" --version 2>/dev/null || echo 'version unknown'))" >&2
  ext=png; [[ $rmse == 1 ]] && ext=exr
  for s in "${scene_list[@]}"; do
    for b in "${backend_list[@]}"; do
      "$veach_bin" render "$scenes_dir/$s.gltf" --backend "$b" --width 16 --height 16 --spp 1 \
        --max-depth "$depth" -o "$out_dir/warmup.png" > /dev/null 2>&1 \
        || die "veach warm-up failed: $veach_bin render $scenes_dir/$s.gltf --backend $b"
      for ((i = 1; i <= repeat; i++)); do
        stats="$out_dir/${s}_veach-${b}_$i.json"
        img="$out_dir/${s}_veach-${b}.$ext"
        ref_args=()
        ref=$(reference_for "$s")
        [[ $rmse == 1 && -n $ref ]] && ref_args=(--reference "$ref")
        if ! "$veach_bin" render "$scenes_dir/$s.gltf" --backend "$b" --width "$size" --height "$size" \
            --spp "$spp" --max-depth "$depth" --seed "$seed" --sampler "$veach_sampler" --stats-json "$stats" \
            -o "$img" "${ref_args[@]}" \
            > "$out_dir/veach.log" 2>&1; then
          cat "$out_dir/veach.log" >&2
          die "veach render failed: $s, backend $b"
        fi
        sps=$(sed -n 's/.*"samples_per_second": *\([0-9.eE+-]*\).*/\1/p' "$stats")
        echo "  $(printf '%-8s veach-%-6s' "$s" "$b") run $i: $(awk -v x="$sps" 'BEGIN { printf "%.3f", x / 1e6 }') Msamples/s" >&2
        img_col=""; [[ $ext == exr ]] && img_col=$img
        printf '%s\tveach-%s\t%s\t%s\n' "$s" "$b" "$stats" "$img_col" >> "$veach_tsv"
      done
    done
  done
fi

# ---- Mitsuba --------------------------------------------------------------------------------
mitsuba_json="$out_dir/mitsuba.json"
scene_args=()
for s in "${scene_list[@]}"; do scene_args+=(--scene "$s"); done
exr_args=()
if [[ $rmse == 1 ]]; then
  # Mitsuba's error series reaches at least veach's longest render time.
  longest=$(cat "$out_dir"/*_veach-*.json 2>/dev/null | sed -n 's/.*"seconds_render": *\([0-9.eE+-]*\).*/\1/p' | sort -g | tail -1)
  exr_args=(--exr-dir "$out_dir" --ref-dir "$scenes_dir" --series-seconds "${longest:-0}")
fi
if [[ -n $variants ]]; then
  echo "mitsuba: $("$py" -c 'import mitsuba; print(mitsuba.__version__)') in $venv, variants $variants${DRJIT_LIBLLVM_PATH:+, LLVM $DRJIT_LIBLLVM_PATH}" >&2
fi
"$py" "$here/mitsuba_scenes.py" bench --scenes "$scenes_dir" "${scene_args[@]}" --variants "$variants" \
  --size "$size" --spp "$spp" --depth "$depth" --rr-depth "$rr_depth" --seed "$seed" \
  --repeat "$repeat" "${exr_args[@]}" --out "$mitsuba_json"

# ---- report ---------------------------------------------------------------------------------
report_args=(--mitsuba "$mitsuba_json" --veach-runs "$veach_tsv")
[[ $rmse == 1 ]] && report_args+=(--ref-dir "$scenes_dir" --series-dir "$out_dir")
[[ -n $json_out ]] && report_args+=(--json "$json_out")
"$py" "$here/mitsuba_scenes.py" report "${report_args[@]}"
if [[ $rmse == 1 ]]; then
  for s in "${scene_list[@]}"; do
    files=("$out_dir/${s}"_*.series.json)
    [[ -f ${files[0]} ]] || continue
    "$veach_bin" plot-convergence "${files[@]}" -o "$out_dir/convergence_$s.png" >/dev/null 2>&1 \
      && echo "error against time: $out_dir/convergence_$s.png"
  done
  echo "images and stats kept in $out_dir"
fi
