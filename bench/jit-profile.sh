#!/usr/bin/env bash
# Where lavapipe spends the kernel's time, read from the JIT'd machine code: no debug Mesa.
#
# Starts `veach render SCENE --spp 100000 ...` on the GPU backend, lets it warm up, samples it
# with `perf record -p` (anonymous JIT memory shows up as bare addresses), dumps the JIT'd code
# of the still-running process with gdb, disassembles it with objdump and joins the two:
#   OUT_DIR/jit.annot   every instruction with its sample count
#   stdout              the share of samples in JIT code, in lavapipe's per-lane load loops
#                       (one iteration per SIMD lane: a storage-buffer load is scalarised),
#                       and the hottest 512-byte regions with their instruction mix
#
# Usage: bench/jit-profile.sh [SCENE.gltf] [--warmup S] [--seconds S] [--out-dir DIR] [-- RENDER ARGS...]
#   default scene assets/cornell-box.gltf, 8 s warm-up, 10 s of samples, 256x256
# Needs perf (linux-perf), gdb and objdump (binutils), and ptrace rights over the child (root,
# or kernel.yama.ptrace_scope=0). Environment: VEACH (binary, default target/release/veach).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scene="$root/assets/cornell-box.gltf"
warmup=8
seconds=10
out=""
extra=(--width 256 --height 256)
while [ $# -gt 0 ]; do
    case "$1" in
        --warmup) warmup=$2; shift 2 ;;
        --seconds) seconds=$2; shift 2 ;;
        --out-dir) out=$2; shift 2 ;;
        --) shift; extra=("$@"); break ;;
        -*) echo "jit-profile: unknown option $1" >&2; exit 2 ;;
        *) scene=$1; shift ;;
    esac
done
for tool in perf gdb objdump python3; do
    command -v "$tool" >/dev/null || { echo "jit-profile: needs $tool (apt-get install linux-perf gdb binutils python3)" >&2; exit 2; }
done
veach=${VEACH:-$root/target/release/veach}
[ -x "$veach" ] || { echo "jit-profile: no binary at $veach (cargo build --release)" >&2; exit 2; }
out=${out:-$(mktemp -d)}
mkdir -p "$out"

"$veach" render "$scene" --backend gpu --spp 100000 "${extra[@]}" -o "$out/unused.exr" >"$out/render.log" 2>&1 &
pid=$!
trap 'kill $pid 2>/dev/null || true' EXIT
sleep "$warmup"
kill -0 $pid 2>/dev/null || { echo "jit-profile: the render ended early:" >&2; cat "$out/render.log" >&2; exit 2; }
perf record -q -o "$out/perf.data" -p $pid -- sleep "$seconds" 2>/dev/null
# Every anonymous executable mapping (lavapipe's JIT code; the vdso is named, so excluded),
# from a snapshot of the map: the JIT may map more code while we read.
cp /proc/$pid/maps "$out/maps"
: >"$out/jit.asm"
while read -r range perms _ _ inode rest; do
    [ "$perms" = "r-xp" ] && [ "$inode" = "0" ] && [ -z "$rest" ] || continue
    [[ "$range" =~ ^([0-9a-f]+)-([0-9a-f]+)$ ]] || continue
    start=${BASH_REMATCH[1]} end=${BASH_REMATCH[2]}
    gdb -p $pid -batch -ex "dump binary memory $out/jit-$start.bin 0x$start 0x$end" >/dev/null 2>&1 || continue
    objdump -D -b binary -mi386:x86-64 --adjust-vma=0x"$start" "$out/jit-$start.bin" >>"$out/jit.asm"
done <"$out/maps"
kill $pid 2>/dev/null || true
perf script -i "$out/perf.data" -F ip 2>/dev/null | sort | uniq -c >"$out/ips.txt"

python3 - "$out" <<'EOF'
import collections, re, sys
out = sys.argv[1]
counts = {}
for line in open(f"{out}/ips.txt"):
    c, ip = line.split()
    counts[int(ip, 16)] = int(c)
total = sum(counts.values())
rows = []
with open(f"{out}/jit.annot", "w") as annot:
    for line in open(f"{out}/jit.asm"):
        m = re.match(r"\s*([0-9a-f]+):\s+(?:[0-9a-f]{2} )+\s*(.*)", line)
        if m:
            a = int(m.group(1), 16)
            rows.append((a, counts.get(a, 0), m.group(2).strip()))
            annot.write(f"{counts.get(a, 0):7d} {line.rstrip()}\n")
jit = sum(c for _, c, _ in rows)
print(f"samples: {total}, in JIT code: {jit} ({100 * jit / max(total, 1):.1f} %)")
# Per-lane loops: a backward branch over a short body that counts a lane index to 8.
index = {a: i for i, (a, _, _) in enumerate(rows)}
in_loop = set()
for i, (a, _, text) in enumerate(rows):
    m = re.match(r"j\w+\s+0x([0-9a-f]+)", text)
    if m and int(m.group(1), 16) < a and int(m.group(1), 16) in index:
        j = index[int(m.group(1), 16)]
        if i - j < 80 and any("cmp    $0x8,%e" in t for _, _, t in rows[j:i + 1]):
            in_loop.update(range(j, i + 1))
lane = sum(rows[k][1] for k in in_loop)
print(f"in per-lane (scalarised load) loops: {100 * lane / max(jit, 1):.1f} % of JIT samples")
regions = collections.Counter()
for a, c, _ in rows:
    regions[a // 512 * 512] += c
print("hottest 512-byte regions (% of JIT samples):")
for start, c in regions.most_common(12):
    ops = collections.Counter()
    for a, n, t in rows:
        if start <= a < start + 512 and t:
            ops[t.split()[0]] += n
    mix = ", ".join(f"{op} {100 * n / max(c, 1):.0f}%" for op, n in ops.most_common(4))
    print(f"  {start:#x}  {100 * c / max(jit, 1):5.1f} %   {mix}")
print(f"annotated code: {out}/jit.annot")
EOF
