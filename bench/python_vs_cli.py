#!/usr/bin/python3
"""What meshing from Python costs against the CLI: the same volume file meshed by
`segmesh mesh FILE -o OUT.ply --report R.json --quiet` and by segmesh.mesh_file(FILE) +
segmesh.write(parts, OUT.ply) (the report's numbers are measured by both), alternated, ROUNDS
rounds each; prints each run's wall time, the medians and their ratio. Without FILE, the phantom
(`segmesh phantom`, default size) is written first.

    PYTHONPATH=build/python bench/python_vs_cli.py build OUT_DIR [FILE|""] [ROUNDS]
"""

import os
import statistics
import subprocess
import sys
import time

import segmesh


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    build, out = sys.argv[1], sys.argv[2]
    cli = os.path.join(build, "apps", "cli", "segmesh")
    os.makedirs(out, exist_ok=True)
    given = sys.argv[3] if len(sys.argv) > 3 else ""
    volume = given or os.path.join(out, "phantom.nii.gz")
    rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
    if not given and not os.path.exists(volume):
        subprocess.run([cli, "phantom", "-o", volume, "--quiet"], check=True)
    times = {"cli": [], "python": []}
    for r in range(rounds):
        for who in (("cli", "python") if r % 2 == 0 else ("python", "cli")):
            start = time.perf_counter()
            if who == "cli":
                subprocess.run([cli, "mesh", volume, "-o", os.path.join(out, "cli.ply"), "--report",
                                os.path.join(out, "cli.json"), "--quiet"], check=True)
            else:
                parts = segmesh.mesh_file(volume)
                segmesh.write(parts, os.path.join(out, "python.ply"))
                del parts
            times[who].append(time.perf_counter() - start)
            print(f"round {r + 1} {who:6s} {times[who][-1]:.3f} s", flush=True)
    cli_s, py_s = statistics.median(times["cli"]), statistics.median(times["python"])
    print(f"median: cli {cli_s:.3f} s, python {py_s:.3f} s, python/cli {py_s / cli_s:.3f}")


if __name__ == "__main__":
    main()
