#!/usr/bin/env python3
"""Times two or more velvet binaries on one command, alternating them run by run so that a change
in the machine's load meets each alike; prints the median and fastest wall time of each.

    python3 benches/ab.py RUNS BINARY[,BINARY...] ARGS...
    python3 benches/ab.py 21 /tmp/velvet-before,target/release/velvet validate --format json large.gltf
"""
import statistics
import subprocess
import sys
import time


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    runs = int(sys.argv[1])
    binaries = sys.argv[2].split(",")
    args = sys.argv[3:]
    times = {b: [] for b in binaries}
    for _ in range(runs):
        for binary in binaries:
            start = time.perf_counter()
            subprocess.run([binary] + args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            times[binary].append(time.perf_counter() - start)
    for binary, t in times.items():
        print(f"{binary}: median {statistics.median(t) * 1000:.1f} ms, fastest {min(t) * 1000:.1f} ms ({runs} runs)")


main()
