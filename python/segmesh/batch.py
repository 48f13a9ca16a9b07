"""python3 -m segmesh.batch: `segmesh batch` on a Dask cluster (docs/COHORTS.md, issue 38).

    python3 -m segmesh.batch INPUTS... -o OUT [--workers N | --scheduler tcp://HOST:PORT]
        [--shard I/N] [--force] [--allow-external-data] [--retries R] [meshing options]

The cohort is expanded, named, sharded and checked as `segmesh batch` does it (segmesh.cohort);
each case is one Dask task calling segmesh.run_case, the library's case runner, so a case's folder
appears complete or not at all and OUT/summary.csv is the CLI's (same columns, order and
statuses; rewritten after every case). Exit code 0 when every case is ok or skipped, 1 when any
failed, 2 for a bad argument (nothing written).

--workers N (default 2) starts a dask.distributed LocalCluster of N worker processes, one thread
each, on loopback; --scheduler ADDRESS uses an existing cluster whose workers can import segmesh
and see INPUTS and OUT at the same paths. A worker that dies while meshing a case (killed, out of
memory, its machine lost) has the case run again on another worker, up to --retries times
(the scheduler's allowed-failures; on a cluster of your own, its own setting applies), then the
case is recorded as failed with a message saying so, and what the dead attempts left (hidden
.CASE.tmp-<pid> folders) is removed. A retry is safe: a case is written into a hidden sibling
and renamed into place at the end, and a new attempt removes the case's own leftovers first.
"""

import argparse
import ctypes.util
import os
import sys
import time
import uuid

import segmesh
from segmesh.cases import _MAX_VOXELS, _run_task


def _parser():
    p = argparse.ArgumentParser(
        prog="python3 -m segmesh.batch",
        description="Mesh a cohort on a Dask cluster: every case into OUT/CASE/ (meshes, "
                    "report.json) and OUT/summary.csv, as `segmesh batch` (docs/COHORTS.md).")
    p.add_argument("inputs", nargs="+", help="volume files, folders of them (or of DICOM series), "
                   "globs, or a .csv/.tsv manifest with a path column and per-case option columns")
    p.add_argument("-o", "--output", required=True, help="output folder: OUT/CASE/ per case")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="worker processes of a local cluster (default 2)")
    where.add_argument("--scheduler", help="address of an existing Dask scheduler, tcp://HOST:PORT")
    p.add_argument("--retries", type=int, default=2,
                   help="runs of a case after its worker died or its task raised (default 2)")
    p.add_argument("--shard", help="I/N: only the cases whose index modulo N is I-1")
    p.add_argument("--force", action="store_true", help="redo cases already finished in OUT")
    p.add_argument("--allow-external-data", action="store_true",
                   help="read detached data files outside their header's folder")
    p.add_argument("--format", default="glb", help="mesh format: glb, ply, stl, obj")
    p.add_argument("--per-part", action="store_true", help="one mesh file per part")
    p.add_argument("--quantize", action="store_true", help="glb: KHR_mesh_quantization")
    p.add_argument("--color", default="material", help="vertex colours: material or quality")
    p.add_argument("--threads", type=int, help="threads per case (default: a local cluster's "
                   "cores shared by its workers; 0, all cores, on a --scheduler cluster)")
    p.add_argument("--max-voxels", type=int, default=_MAX_VOXELS, help="refuse larger volumes")
    p.add_argument("--label-names", help="TSV file: label, name[, role bone|implant|other]")
    p.add_argument("--quiet", action="store_true", help="no progress line per case")
    mesh = p.add_argument_group("meshing options (segmesh mesh's)")
    for spec in segmesh.options():
        name, dest = spec["name"], "mesh_" + spec["keyword"]
        if spec["type"] == "FLAG":
            mesh.add_argument(f"--no-{name}", dest=dest, action="store_false", default=None,
                              help=spec["help"])
        elif spec["type"].endswith("LIST"):
            mesh.add_argument(f"--{name}", dest=dest, nargs="+", help=spec["help"])
        else:
            mesh.add_argument(f"--{name}", dest=dest, help=f"{spec['help']} (default {spec['default']})"
                              if spec["default"] else spec["help"])
    return p


def _options(args):
    """The meshing options given, by keyword: text as on the command line, flags as False."""
    out = {}
    for key, value in vars(args).items():
        if not key.startswith("mesh_") or value is None:
            continue
        out[key[len("mesh_"):]] = ",".join(value) if isinstance(value, list) else value
    return out


def _settings(args, threads):
    """run_case's keyword arguments shared by every case."""
    return dict(force=args.force, format=args.format, per_part=args.per_part,
                quantize=args.quantize, color=args.color, threads=threads,
                max_voxels=args.max_voxels, allow_external_data=args.allow_external_data,
                label_names=args.label_names, **_options(args))


def _failed(case, error):
    return {"case": case["name"], "input": case["input"], "status": "failed", "parts": 0,
            "triangles": 0, "volume_mm3": 0.0, "seconds": 0.0, "error": error}


def run_cohort(cases, out_dir, client, settings, *, retries=2, quiet=False):
    """Runs `cases` (segmesh.cohort's) on `client` (a dask.distributed Client), one task per
    case calling segmesh.run_case with `settings`; writes out_dir's summary after every case.
    Returns the rows in input order."""
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    summary = os.path.join(out_dir, segmesh.summary_file_name(cases.shard))
    rows = [{"case": c["name"], "input": c["input"], "status": "pending"} for c in cases]
    segmesh.write_summary(summary, rows)
    token = uuid.uuid4().hex[:8]  # keys unique on a shared scheduler; the case's name to read
    futures = {}
    for i, c in enumerate(cases):
        future = client.submit(_run_task, c, out_dir, settings,
                               key=f"segmesh-{c['name']}-{token}", retries=retries, pure=False)
        futures[future] = i
    failed = 0
    for done, future in enumerate(as_completed(futures), 1):
        i = futures[future]
        c = cases[i]
        try:
            row = future.result()
        except KilledWorker:
            segmesh._segmesh.remove_case_temporaries(out_dir, c["name"])
            row = _failed(c, f"{c['input']}: the worker meshing it died (killed, or out of "
                             "memory) on every attempt; not tried again")
        except Exception as e:  # the task raised on every try: the case fails, the rest go on
            segmesh._segmesh.remove_case_temporaries(out_dir, c["name"])
            row = _failed(c, f"{c['input']}: {type(e).__name__}: {e}".replace("\n", " "))
        for message in row.pop("warnings", []):
            print(f"segmesh: warning: {c['name']}: {message}", file=sys.stderr)
        rows[i] = row
        segmesh.write_summary(summary, rows)
        failed += row["status"] == "failed"
        if not quiet:
            error = f": {row['error']}" if row["error"] else ""
            print(f"[{done}/{len(cases)}] {row['case']} {row['status']} {row['seconds']:.1f} s{error}",
                  file=sys.stderr, flush=True)
    if not quiet:
        shard = f" (shard {cases.shard[0]}/{cases.shard[1]})" if cases.shard[1] > 1 else ""
        print(f"{len(cases)} cases ({failed} failed) of {cases.total}{shard}; summary {summary}",
              file=sys.stderr)
    return rows


def _worker_allocator():
    """Environment for the local workers: jemalloc on huge pages, preloaded, as the `segmesh`
    program allocates (docs/PERFORMANCE.md, "The programs' allocator": twice as fast on the
    phantom), where jemalloc is installed (Debian's libjemalloc2) and this environment preloads
    nothing already (LD_PRELOAD set, even empty, leaves the workers as they are)."""
    if "LD_PRELOAD" in os.environ:
        return {}
    name = ctypes.util.find_library("jemalloc")
    if not name:
        return {}
    return {"LD_PRELOAD": name,
            "MALLOC_CONF": os.environ.get("MALLOC_CONF", "thp:always,metadata_thp:auto")}


def _local_cluster(workers, retries):
    import dask
    from distributed import LocalCluster

    # The scheduler runs in this process: a case is rescheduled after its worker died this
    # many times. No dashboard (no fixed port to collide on), no memory limit (as the CLI:
    # a case that runs out of memory fails on its own), loopback only. The worker processes
    # start with the programs' allocator (_worker_allocator).
    environ = {**dask.config.get("distributed.nanny.pre-spawn-environ", {}), **_worker_allocator()}
    with dask.config.set({"distributed.scheduler.allowed-failures": retries,
                          "distributed.nanny.pre-spawn-environ": environ}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            host="127.0.0.1", dashboard_address=None, memory_limit=0)


def main(argv=None, client=None):
    """The command line; `client`: an existing dask.distributed Client to run on instead."""
    args = _parser().parse_args(argv)
    prog = "segmesh.batch"
    workers = args.workers if args.workers is not None else 2
    if workers < 1:
        print(f"{prog}: error: --workers must be at least 1", file=sys.stderr)
        return 2
    if args.retries < 0:
        print(f"{prog}: error: --retries must be 0 or more", file=sys.stderr)
        return 2
    local = client is None and args.scheduler is None
    threads = args.threads
    if threads is None:
        threads = max(1, (os.cpu_count() or 1) // workers) if local else 0
    settings = _settings(args, threads)
    out = args.output
    try:
        cases = segmesh.cohort(args.inputs, out, shard=args.shard, **settings)
        out = cases.out_dir
        if os.path.exists(out) and not os.path.isdir(out):
            raise ValueError(f"{args.output}: exists and is not a folder; -o names the output folder")
        parent = os.path.dirname(os.path.abspath(out))
        if not os.path.isdir(parent):
            raise ValueError(f"{args.output}: its folder {parent} does not exist")
    except ValueError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    os.makedirs(out, exist_ok=True)
    start = time.monotonic()
    if client is not None:
        rows = run_cohort(cases, out, client, settings, retries=args.retries, quiet=args.quiet)
    else:
        from distributed import Client

        cluster = _local_cluster(workers, args.retries) if local else None
        try:
            with Client(cluster if local else args.scheduler) as own:
                rows = run_cohort(cases, out, own, settings, retries=args.retries,
                                  quiet=args.quiet)
        finally:
            if cluster is not None:
                cluster.close()
    if not args.quiet:
        print(f"{prog}: {time.monotonic() - start:.1f} s", file=sys.stderr)
    return 1 if any(r["status"] == "failed" for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
