#!/usr/bin/env python3
"""Times the step 3D Slicer runs after its windowed-sinc smoothing: vertex normals.

Slicer's closed-surface conversion (Libs/vtkSegmentationCore/
vtkBinaryLabelmapToClosedSurfaceConversionRule.cxx) ends, with its default "compute surface
normals" on, with vtkPolyDataNormals (ConsistencyOn, SplittingOff) on the smoothed mesh.
../shared/tools/peer_mesh.py times the extraction and the smoothing but not this step, while
segmesh's smoothing recomputes the normals inside its own time. This script makes the smoothed
surface of every label as peer_mesh.py does (each label cropped to its box and padded by one voxel,
vtkDiscreteFlyingEdges3D, vtkWindowedSincPolyDataFilter with Slicer's settings: 20 iterations,
pass band 0.01, boundary and feature-edge smoothing off, non-manifold smoothing on, normalised
coordinates), untimed, and times only the normals (best of --repeats, summed over the labels).
Slicer's IJK-to-world transform between the two is not timed either.

    slicer_normals.py LABELMAP --threads T [--repeats N]

Prints one JSON object: {"threads": T, "normals_s": ..., "labels": ..., "points": ...}.
Needs Debian's python3-vtk9, python3-nibabel and python3-numpy (scripts/install-deps.sh
--with-peers).
"""
import argparse
import json
import sys
import time

import nibabel
import numpy
import vtk
from vtk.util import numpy_support


def smoothed_surface(mask, spacing):
    """The label's surface after Slicer's windowed-sinc smoothing (untimed)."""
    image = vtk.vtkImageData()
    image.SetDimensions(*mask.shape)
    image.SetSpacing(*spacing)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(
        mask.ravel(order="F"), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR))
    extract = vtk.vtkDiscreteFlyingEdges3D()
    extract.SetInputData(image)
    extract.SetValue(0, 1)
    extract.ComputeNormalsOff()
    extract.ComputeGradientsOff()
    extract.ComputeScalarsOff()
    smooth = vtk.vtkWindowedSincPolyDataFilter()
    smooth.SetInputConnection(extract.GetOutputPort())
    smooth.SetNumberOfIterations(20)
    smooth.SetPassBand(0.01)
    smooth.BoundarySmoothingOff()
    smooth.FeatureEdgeSmoothingOff()
    smooth.NonManifoldSmoothingOn()
    smooth.NormalizeCoordinatesOn()
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
    image = nibabel.load(args.labelmap)
    labels = numpy.asarray(image.dataobj)
    spacing = [float(s) for s in image.header.get_zooms()[:3]]
    total, points = 0.0, 0
    values = [int(v) for v in numpy.unique(labels) if v != 0]
    for value in values:
        where = numpy.nonzero(labels == value)
        lo = [int(w.min()) for w in where]
        hi = [int(w.max()) + 1 for w in where]
        crop = labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] == value
        mask = numpy.pad(crop, 1).astype(numpy.uint8)  # its box and one voxel of background
        surface = smoothed_surface(mask, spacing)
        points += surface.GetNumberOfPoints()
        total += time_normals(surface, args.repeats)
    print(json.dumps({"threads": args.threads, "normals_s": total, "labels": len(values),
                      "points": points}))


if __name__ == "__main__":
    main(sys.argv[1:])
