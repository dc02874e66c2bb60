#!/usr/bin/env python3
"""Functions of veach's that call AVX intrinsics out of line.

    bench/avx_calls.py BINARY

On x86-64 the lanes' operations are AVX intrinsics (`cpu/lanes/lane.rs`) inlined into the
kernels compiled for AVX2. Code the compiler leaves out of line (a closure it does not
inline, say) is compiled without AVX, so each lane operation in it becomes a call to the
intrinsic's own function: the same bits, several times slower (session 35 found a closure of
`sample_lights` so and lost 28 % of the Cornell box to another). Prints each such function
with its number of calls; exit status 1 when there is one, 0 when there is none, 2 on bad
input."""

import collections
import re
import subprocess
import sys


def main():
    if len(sys.argv) != 2:
        print("usage: bench/avx_calls.py BINARY", file=sys.stderr)
        sys.exit(2)
    binary = sys.argv[1]
    dis = subprocess.run(["objdump", "-d", "-C", "--no-show-raw-insn", binary], capture_output=True, text=True)
    if dis.returncode != 0:
        print(f"avx_calls: objdump failed on '{binary}': {dis.stderr.strip()}", file=sys.stderr)
        sys.exit(2)
    calls, function = collections.Counter(), None
    for line in dis.stdout.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.*)>:$", line)
        if m:
            function = m.group(1)
        elif "call" in line and "core_arch::x86" in line and function and function.startswith("veach::"):
            calls[function] += 1
    for function, n in calls.most_common():
        print(f"{n:6d}  {function}")
    if not calls:
        print("avx_calls: no function of veach's calls an AVX intrinsic out of line")
    sys.exit(1 if calls else 0)


if __name__ == "__main__":
    main()
