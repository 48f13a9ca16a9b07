#!/usr/bin/env python3
"""Times the step 3D Slicer runs after its windowed-sinc smoothing: vertex normals.

Slicer's closed-surface conversion (Libs/vtkSegmentationCore/
vtkBinaryLabelmapToClosedSurfaceConversionRule.cxx) ends, with its default "compute surface
normals" on, with vtkPolyDataNormals (ConsistencyOn, SplittingOff) on the smoothed mesh.
../shared/tools/peer_mesh.py times the extraction and the smoothing but not this step, while
segmesh's smoothing recomputes the normals inside its own time. This script makes the smoothed
surface of every label with peer_mesh.py's own functions and defaults (the label cropped to its
box and padded by one voxel, vtkDiscreteFlyingEdges3D, vtkWindowedSincPolyDataFilter with
Slicer's settings), so it is the surface peer_mesh.py timed, untimed here, and times only the
normals (best of --repeats, summed over the labels). Slicer's IJK-to-world transform between the
two is not timed either.

    slicer_normals.py LABELMAP --threads T [--repeats N]

Prints one JSON object: {"threads": T, "normals_s": ..., "labels": ..., "points": ...}.
Needs ../shared/tools/peer_mesh.py beside the repository and Debian's python3-vtk9,
python3-nibabel and python3-numpy (scripts/install-deps.sh --with-peers).
"""
import argparse
import json
import pathlib
import sys
import time

import numpy
import vtk

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "shared" / "tools"))
import peer_mesh  # noqa: E402


def smoothed_surface(labels, value, box, spacing, options):
    """The label's surface after Slicer's windowed-sinc smoothing, as peer_mesh.py makes it."""
    lo, hi = box
    sub = peer_mesh.crop_pad(labels, lo, hi, True, 0)
    image = peer_mesh.to_vtk_image(sub, spacing, (lo - 1) * numpy.asarray(spacing))
    extract = peer_mesh.build_extractor("discrete_fe", image, None, value, None)
    extract.Update()
    smooth = peer_mesh.build_smoother("sinc", extract.GetOutput(), options)
    smooth.Update()
    return smooth.GetOutput()


def time_normals(surface, repeats):
    best = float("inf")
    for _ in range(repeats):
        normals = vtk.vtkPolyDataNormals()
        normals.SetInputData(surface)
        normals.ConsistencyOn()
        normals.SplittingOff()
        start = time.perf_counter()
        normals.Update()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("labelmap")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    vtk.vtkSMPTools.Initialize(args.threads)
    labels, spacing, _ = peer_mesh.load_volume(args.labelmap)
    # peer_mesh.py's defaults: Slicer's smoothing factor (pass band 0.01), 20 iterations.
    options = peer_mesh.parse_args([args.labelmap])
    values = [int(v) for v in numpy.unique(labels) if v != 0]
    total, points = 0.0, 0
    for value, box in peer_mesh.label_boxes(labels, values).items():
        surface = smoothed_surface(labels, value, box, spacing, options)
        points += surface.GetNumberOfPoints()
        total += time_normals(surface, args.repeats)
    print(json.dumps({"threads": args.threads, "normals_s": total, "labels": len(values),
                      "points": points}))


if __name__ == "__main__":
    main(sys.argv[1:])
