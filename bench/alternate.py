#!/usr/bin/python3
"""Whole `segmesh mesh` commands, alternated round by round, as users run them.

Each VARIANT is NAME=BINARY or NAME=BINARY:OPTIONS (a segmesh program and extra options); every
round runs each variant once on each input, in an order that rotates between rounds, and the table
gives per variant the median wall time, peak memory (maximum resident set) and minor page faults,
and the wall-time and memory ratios to the first variant in the same run. Used for the
conforming-against-independent ratio of issue 35 and for the programs' allocator
(docs/PERFORMANCE.md).

  bench/alternate.py [--rounds N] [--threads T] INPUT[,INPUT...] VARIANT [VARIANT ...]
  bench/alternate.py --rounds 9 phantom.nii.gz \\
      default=build/apps/cli/segmesh 'independent=build/apps/cli/segmesh:--surfaces independent'
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("inputs")
    ap.add_argument("variants", nargs="+")
    a = ap.parse_args()
    variants = []
    for v in a.variants:
        name, _, spec = v.partition("=")
        binary, _, options = spec.partition(":")
        if not name or not binary:
            sys.exit(f"alternate: a variant is NAME=BINARY[:OPTIONS], not {v!r}")
        variants.append((name, binary, options.split()))
    # The meshes written go to a folder removed at the end (a big map's GLB is 100 MB or more).
    with tempfile.TemporaryDirectory(prefix="segmesh_alternate_") as out:
        for path in a.inputs.split(","):
            table(path, out, variants, a.rounds, a.threads)


def table(path, out, variants, rounds, threads):
    """Runs every variant `rounds` times on `path`, rotating the order, and prints the medians."""
    results = {name: [] for name, _, _ in variants}
    for r in range(rounds):
        order = variants[r % len(variants):] + variants[:r % len(variants)]
        for name, binary, options in order:
            glb = os.path.join(out, name + ".glb")
            # /usr/bin/time -f gives this command's own peak memory.
            cmd = ["/usr/bin/time", "-f", "%M", binary, "mesh", path, "-o", glb,
                   "--threads", str(threads), "--quiet"] + options
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            if p.returncode != 0:
                sys.exit(f"alternate: {' '.join(cmd)} failed: {p.stderr.strip()}")
            peak_kb = int(p.stderr.strip().splitlines()[-1])
            results[name].append((wall, peak_kb, after.ru_minflt - before.ru_minflt))
    print(f"{os.path.basename(path)}, {rounds} rounds, {threads} threads (medians)")
    print("| variant | wall s | min-max s | peak MB | minor faults | time ratio | memory ratio |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    first = None
    for name, _, _ in variants:
        rows = results[name]
        wall = statistics.median(w for w, _, _ in rows)
        peak = statistics.median(m for _, m, _ in rows) / 1024
        faults = statistics.median(f for _, _, f in rows)
        if first is None:
            first = (wall, peak)
        print(f"| {name} | {wall:.3f} | {min(w for w, _, _ in rows):.3f}-"
              f"{max(w for w, _, _ in rows):.3f} | {peak:.0f} | {faults:.0f} | "
              f"{wall / first[0]:.2f} | {peak / first[1]:.2f} |")
    print()


if __name__ == "__main__":
    main()
