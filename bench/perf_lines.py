#!/usr/bin/env python3
"""Where one hot function's samples go, by the source line of veach's own code.

    perf record -o perf.data -F 4000 <veach render ...>
    bench/perf_lines.py perf.data path/to/veach resample_lights_avx2 [LINES]

The lanes kernels inline everything into a few huge functions, and `perf report --sort srcline`
names the innermost frame, which there is almost always one of `lane.rs`'s one-line operations.
This maps each sample's offset in FUNCTION through `objdump --inlines` to the first frame in
veach's sources outside `cpu/lanes/lane.rs` (and outside the standard library), then prints the
share of samples and the number of instructions per enclosing function and per line. Comparing
two builds this way found session 34's partly scalarised importance (BENCHMARKS.md).
"""
import collections
import re
import subprocess
import sys


def main():
    if len(sys.argv) < 4:
        print("usage: bench/perf_lines.py PERF_DATA BINARY FUNCTION [LINES]", file=sys.stderr)
        sys.exit(2)
    data, binary, function = sys.argv[1:4]
    if len(sys.argv) > 4 and not sys.argv[4].isdigit():
        fail(f"perf_lines: LINES must be a count, not '{sys.argv[4]}'")
    lines = int(sys.argv[4]) if len(sys.argv) > 4 else 30

    script = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym,symoff"], capture_output=True, text=True)
    if script.returncode != 0:
        fail(f"perf_lines: perf script failed on '{data}': {script.stderr.strip()}")
    offsets = collections.Counter()
    pattern = re.compile(r"::" + re.escape(function) + r"\+0x([0-9a-f]+)")
    for line in script.stdout.splitlines():
        m = pattern.search(line)
        if m:
            offsets[int(m.group(1), 16)] += 1

    symbols = subprocess.run(["nm", binary], capture_output=True, text=True).stdout.splitlines()
    # The function itself, not every symbol containing its name (`trace_pair` is also a prefix
    # of `trace_pair_avx2`): a mangled path's last part is LENGTH NAME, then the hash (and a
    # ".llvm.N" suffix where LLVM made the symbol local).
    exact = re.compile(str(len(function)) + re.escape(function) + r"17h[0-9a-f]{16}E(\.llvm\.\d+)?$")
    mangled = [s.split()[2] for s in symbols if len(s.split()) == 3 and exact.search(s.split()[2])]
    if len(mangled) != 1:
        fail(f"perf_lines: {len(mangled)} functions named '{function}' in '{binary}' (need exactly one)")
    dis = subprocess.run(
        ["objdump", "-d", "-l", "--inlines", "--no-show-raw-insn", "--disassemble=" + mangled[0], binary],
        capture_output=True,
        text=True,
    ).stdout

    # Each instruction's inline chain, innermost first: (file, line, function the line is in).
    # objdump names the innermost frame's function on a line "name():" before its location,
    # and each outer frame as "inlined by FILE:LINE (name)".
    chain, innermost, place = [], "", {}
    for line in dis.splitlines():
        m = re.match(r"^(\S+)\(\):$", line)
        if m:
            innermost = m.group(1)
            continue
        m = re.match(r"^(/\S+):(\d+)", line)
        if m:
            chain = [(m.group(1), m.group(2), innermost)]
            continue
        m = re.match(r"^inlined by (\S+):(\d+) \((.*)\)", line)
        if m and chain:
            chain.append((m.group(1), m.group(2), m.group(3)))
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+\S+", line)
        if m:
            place[int(m.group(1), 16)] = own_frame(chain, function)
    if not place:
        fail(f"perf_lines: objdump gave no instructions for '{mangled[0]}'")

    base = min(place)
    total = sum(offsets.values()) or 1
    by_line, by_fn = collections.Counter(), collections.Counter()
    size_line, size_fn = collections.Counter(), collections.Counter()
    for where, fn in place.values():
        size_line[where] += 1
        size_fn[fn] += 1
    for off, n in offsets.items():
        where, fn = place.get(base + off, ("?", "?"))
        by_line[where] += n
        by_fn[fn] += n
    print(f"{function}: {sum(offsets.values())} samples, {len(place)} instructions")
    print("share  instrs  enclosing function")
    for fn, n in by_fn.most_common(lines):
        print(f"{100 * n / total:5.1f}% {size_fn[fn]:6d}  {fn}")
    print("share  instrs  line")
    for where, n in by_line.most_common(lines):
        print(f"{100 * n / total:5.1f}% {size_line[where]:6d}  {where}")


def fail(message):
    print(message, file=sys.stderr)
    sys.exit(2)


def own_frame(chain, function):
    """The first frame in veach's sources that is not a lane operation, and its function
    (objdump names the outermost one by its mangled symbol: that is FUNCTION)."""
    for f, n, fn in chain:
        if "/src/" in f and "/rustc/" not in f and "/.cargo/" not in f and not f.endswith("lanes/lane.rs"):
            return f.split("/src/")[-1] + ":" + n, function if fn.startswith("_ZN") else fn[:60]
    return "?", "?"


if __name__ == "__main__":
    main()
