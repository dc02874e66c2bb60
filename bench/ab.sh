#!/usr/bin/env bash
# A/B throughput of two commits of the CPU engine, measured the way BENCHMARKS.md asks:
# both built in the same way, run alternately in one session, compared as pairwise ratios.
#
#   bench/ab.sh BASE CANDIDATE [SCENE] [MAX_DEPTH]
#
# BASE and CANDIDATE are git revisions. SCENE defaults to the bundled Cornell box. Environment:
# REPS (alternating pairs, 5), SPP (64), SIZE (128), THREADS (1), SEED (3), EXTRA (more render
# flags, e.g. "--light-sampler tree"), AB_DIR (builds and binaries, /tmp/veach-ab).
#
# Both commits build with every function entry on a 64-byte boundary
# (-Cllvm-args=-align-all-functions=6): without it, an unchanged hot function can start at
# another offset within its cache line after an unrelated change, and session 32 measured the
# same trace_pair_avx2 code 13 % slower for that alone. The pinned build is for measuring; it
# is not the release build (the pin measured ≈ 1.00× there, BENCHMARKS.md session 33).
#
# Prints Msamples/s per run (from --stats-json's seconds_render, so loading and BVH build are
# excluded), the pairwise CANDIDATE/BASE ratios with their median, the ratio of each one's best
# run, and whether the two outputs are byte-equal (a restructuring that claims the same bits
# must show "byte-equal"). The worktrees stay registered: after `rm -rf $AB_DIR`, run
# `git worktree prune`.
set -euo pipefail

usage() { echo "usage: bench/ab.sh BASE CANDIDATE [SCENE] [MAX_DEPTH]" >&2; exit 2; }
[ $# -ge 2 ] || usage
root=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
scene=${3:-$root/assets/cornell-box.gltf}
depth=${4:-8}
[ -f "$scene" ] || { echo "bench/ab.sh: no scene file '$scene'" >&2; exit 2; }
reps=${REPS:-5} spp=${SPP:-64} size=${SIZE:-128} threads=${THREADS:-1} seed=${SEED:-3}
dir=${AB_DIR:-/tmp/veach-ab}
mkdir -p "$dir"

# The binary of one revision, built once per commit (worktrees share one target directory,
# so the dependencies build once).
binary() {
    local sha bin wt
    sha=$(git -C "$root" rev-parse --verify --quiet --short=12 "$1^{commit}") || { echo "bench/ab.sh: no revision '$1'" >&2; exit 2; }
    bin=$dir/veach-$sha
    if [ ! -x "$bin" ]; then
        wt=$dir/wt-$sha
        [ -d "$wt" ] || git -C "$root" worktree add -q --detach "$wt" "$sha" >&2
        echo "bench/ab.sh: building $sha (pinned function alignment) ..." >&2
        (cd "$wt" && CARGO_TARGET_DIR=$dir/target RUSTFLAGS="-Cllvm-args=-align-all-functions=6" \
            cargo build --release --quiet --bin veach >&2)
        cp "$dir/target/release/veach" "$bin.tmp" && mv "$bin.tmp" "$bin"
    fi
    echo "$bin"
}

a=$(binary "$1")
b=$(binary "$2")
echo "A $1 = $a"
echo "B $2 = $b"
echo "scene $scene, ${size}x$size, $spp spp, depth $depth, $threads thread(s), seed $seed ${EXTRA:-}"

rates() { python3 -c "import json,sys;d=json.load(open(sys.argv[1]));print($size*$size*$spp/d['seconds_render']/1e6)" "$1"; }
ra=() rb=()
for _ in $(seq "$reps"); do
    for x in a b; do
        bin=${!x}
        # shellcheck disable=SC2086 # EXTRA is a list of flags
        RAYON_NUM_THREADS=$threads "$bin" render "$scene" -o "$dir/out_$x.exr" --width "$size" --height "$size" \
            --spp "$spp" --max-depth "$depth" --seed "$seed" ${EXTRA:-} --stats-json "$dir/out_$x.json" >/dev/null 2>"$dir/err_$x.txt" \
            || { echo "bench/ab.sh: render with $bin failed: $(tail -n 1 "$dir/err_$x.txt")" >&2; exit 1; }
        if [ $x = a ]; then ra+=("$(rates "$dir/out_a.json")"); else rb+=("$(rates "$dir/out_b.json")"); fi
    done
done
python3 - "${ra[*]}" "${rb[*]}" <<'PY'
import statistics, sys
a = [float(x) for x in sys.argv[1].split()]
b = [float(x) for x in sys.argv[2].split()]
r = [y / x for x, y in zip(a, b)]
print("A Ms/s", " ".join(f"{x:.3f}" for x in a))
print("B Ms/s", " ".join(f"{x:.3f}" for x in b))
print("B/A   ", " ".join(f"{x:.3f}" for x in r))
print(f"B/A pairwise median {statistics.median(r):.3f} (min {min(r):.3f}, max {max(r):.3f})")
# Interference from other tenants only ever adds time, so the best run of each is the other
# estimate; trust a ratio when the two agree.
print(f"B/A best of each      {max(b) / max(a):.3f}")
PY
if cmp -s "$dir/out_a.exr" "$dir/out_b.exr"; then echo "outputs byte-equal"; else echo "outputs differ"; fi
