"""Cohorts from Python: the library's case runner, the one `segmesh batch` runs (docs/COHORTS.md).

    import segmesh
    cases = segmesh.cohort(["scans/"], "out")              # expanded and checked like the CLI's
    rows = [segmesh.run_case(c, "out", iterations=40) for c in cases]
    segmesh.write_summary("out/summary.csv", rows)        # the CLI's summary.csv

run_case meshes one case into OUT/CASE/ (the meshes, report.json and the completion marker
case.json), atomically: the folder appears complete or not at all. A finished case is skipped, a
bad one is recorded (status "failed", a one-line error naming the file), never raised. Only
segmesh.Cancelled (a progress callback said stop) and KeyboardInterrupt are raised.
"""

import os as _os

from . import _segmesh

__all__ = ["run_case", "cohort", "write_summary", "summary_file_name", "SUMMARY_COLUMNS"]

# The columns of summary.csv, in order (case_summary.hpp).
SUMMARY_COLUMNS = ("case", "input", "status", "parts", "triangles", "volume_mm3", "seconds", "error")

_MAX_VOXELS = 2_000_000_000


def _settings(format, per_part, quantize, color, threads, max_voxels, allow_external_data, force,
              label_names, options):
    return {"format": format, "per_part": bool(per_part), "quantize": bool(quantize),
            "color": color, "threads": int(threads), "max_voxels": int(max_voxels),
            "allow_external_data": bool(allow_external_data), "force": bool(force),
            "label_names": _os.fspath(label_names) if isinstance(label_names, _os.PathLike)
            else label_names, "options": options}


def run_case(input, out_dir, name=None, *, force=False, format="glb", per_part=False,
             quantize=False, color="material", threads=0, max_voxels=_MAX_VOXELS,
             allow_external_data=False, label_names=None, progress=None, **options):
    """Meshes one case of a cohort into out_dir/NAME/ as `segmesh batch` does; returns its row of
    summary.csv as a dict: case, input, status ("ok", "failed", "skipped"), parts, triangles,
    volume_mm3, seconds, error; plus warnings (the reader's).

    input: a volume file or DICOM folder, or an entry of segmesh.cohort() (its name and its
    manifest's per-case options are used). name: the case folder's name (default: the file name
    without its volume extension). force: redo a finished case. format, per_part, quantize,
    color, threads, max_voxels, label_names and **options are `segmesh batch`'s (options by the
    names of segmesh.options(), as for segmesh.mesh); a bad one raises ValueError before anything
    is written. allow_external_data: read a detached header's data file outside its folder
    (refused by default, as in batch runs). progress: callable(step, fraction), as for mesh().
    The GIL is released while the case runs; out_dir is made if missing.
    """
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable(step, fraction), not {type(progress).__name__}")
    if not isinstance(input, dict):
        input = _os.fspath(input)
    settings = _settings(format, per_part, quantize, color, threads, max_voxels,
                         allow_external_data, force, label_names, options)
    return _segmesh.run_case(input, _os.fspath(out_dir), name, settings, progress)


class Cohort(list):
    """The cases of a cohort run (a list of dicts: input, name, options (a manifest row's cells),
    origin, manifest_folder, index in the whole cohort), plus total (cases in the whole cohort,
    every shard's), out_dir (OUT as the runs take it) and shard ((I, N), (1, 1) without one)."""

    def __init__(self, raw):
        super().__init__(raw["cases"])
        self.total = raw["total"]
        self.out_dir = raw["out_dir"]
        self.shard = tuple(raw["shard"])


def cohort(inputs, out_dir, *, shard=None, force=False, format="glb", per_part=False,
           quantize=False, color="material", threads=0, max_voxels=_MAX_VOXELS,
           allow_external_data=False, label_names=None, **options):
    """The cases of `inputs` (volume files, folders, globs, CSV/TSV manifests; a str is one input)
    as `segmesh batch` expands and names them, out_dir left out of the search; with shard="I/N"
    only that shard's. Every case's options (the arguments, as run_case takes them, and a
    manifest row's cells) are checked first: ValueError with the CLI's message (naming the
    manifest's line) for a bad one. Nothing is written. Returns a Cohort (a list of case dicts)."""
    if isinstance(inputs, (str, _os.PathLike)):
        inputs = [inputs]
    settings = _settings(format, per_part, quantize, color, threads, max_voxels,
                         allow_external_data, force, label_names, options)
    return Cohort(_segmesh.cohort([_os.fspath(i) for i in inputs], _os.fspath(out_dir),
                                  shard or "", settings))


def write_summary(path, rows):
    """Writes summary.csv (SUMMARY_COLUMNS; run_case's rows, in the order given) atomically, as
    `segmesh batch` writes it. A row without numbers (status "pending") may hold only case,
    input and status."""
    _segmesh.write_case_summary(_os.fspath(path), list(rows))


def summary_file_name(shard=(1, 1)):
    """"summary.csv", or "summary-I-of-N.csv" for shard (I, N)."""
    return _segmesh.summary_file_name(int(shard[0]), int(shard[1]))


def _run_task(case, out_dir, settings):
    """run_case as one task of a scheduler (segmesh.batch): the shared settings in one dict."""
    return run_case(case, out_dir, **settings)
