#!/usr/bin/python3
"""VTK's vtkQuadricDecimation per part to segmesh's triangle counts (bench/compare_decimation.sh).

    /usr/bin/python3 bench/vtk_decimate.py UNDECIMATED_DIR TARGET_DIR OUT_DIR [--volume-preservation]

UNDECIMATED_DIR holds the PLY per part of `segmesh mesh LABELMAP -o DIR/` (default options);
TARGET_DIR the same parts decimated by segmesh (`--decimate-error 0.2`), whose triangle counts are
the targets. Every part is decimated with SetTargetReduction(1 - target / triangles) and written to
OUT_DIR under the same file name (PLY, binary). Prints one JSON line: the decimation's seconds
(time.perf_counter around Update() only, reading and writing untimed, parts one after another),
the triangles asked and made. Needs Debian's python3-vtk9 (scripts/install-deps.sh --with-peers).
"""
import json
import os
import sys
import time

import vtk


def read_ply(path):
    reader = vtk.vtkPLYReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    if len(args) != 3:
        sys.exit(__doc__)
    undecimated, targets, out = args
    preserve = "--volume-preservation" in sys.argv[1:]
    os.makedirs(out, exist_ok=True)
    seconds = 0.0
    asked = made = 0
    for name in sorted(os.listdir(undecimated)):
        if not name.endswith(".ply"):
            continue
        mesh = read_ply(os.path.join(undecimated, name))
        target = read_ply(os.path.join(targets, name)).GetNumberOfCells()
        decimate = vtk.vtkQuadricDecimation()
        decimate.SetInputData(mesh)
        decimate.SetTargetReduction(1.0 - target / mesh.GetNumberOfCells())
        decimate.SetVolumePreservation(preserve)
        t0 = time.perf_counter()
        decimate.Update()
        seconds += time.perf_counter() - t0
        result = decimate.GetOutput()
        asked += target
        made += result.GetNumberOfCells()
        writer = vtk.vtkPLYWriter()
        writer.SetFileName(os.path.join(out, name))
        writer.SetInputData(result)
        writer.SetFileTypeToBinary()
        writer.Write()
    print(json.dumps({"seconds": seconds, "triangles_asked": asked, "triangles_made": made,
                      "volume_preservation": preserve, "vtk": vtk.vtkVersion.GetVTKVersion()}))


if __name__ == "__main__":
    main()
