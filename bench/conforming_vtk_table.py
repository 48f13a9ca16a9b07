#!/usr/bin/python3
"""Conforming surfaces against independent ones and against VTK, on the same label maps.

For every label map this runs three pipelines and scores them with the same code:
  segmesh conforming    `segmesh mesh MAP -o DIR/ --format ply` (the default, no --surfaces)
  segmesh independent   the same with --surfaces independent
  VTK                   3D Slicer's closed-surface conversion as ../shared/tools/peer_mesh.py runs
                        it: every label cropped to its box plus one voxel, vtkDiscreteFlyingEdges3D,
                        vtkWindowedSincPolyDataFilter (pass band 0.01, 20 iterations, Hamming
                        window: Debian's VTK 9.1 has no vtkSurfaceNets3D and no Nuttall window)
and prints one markdown table. Definitions (the same for all three):

  time          segmesh: wall time of the whole command (read, parts, extract, smooth, write PLY
                files), best of --repeats. VTK: the two filters' Update() summed over the labels,
                best of --repeats; loading, cropping and writing are not timed, which favours VTK.
                Both at --threads threads (vtkSMPTools.Initialize for VTK). The three tools run in
                turn, --repeats rounds, so a change of the host's load reaches all three.
  closed        every part (segmesh: each connected part's file; VTK: each label's mesh) has no
                boundary edge, no edge with more than two triangles, no pinched vertex and a
                consistent winding (../shared/tools/mesh_metrics.py).
  volume error  per label: |mesh volume| / (voxel count x voxel volume) - 1; the median over the
                labels and that of all labels together (summed volumes).
  contact       two labels touch where a voxel of one shares a face with a voxel of the other.
                A contact vertex of label A with label B is a vertex of A's mesh that, before
                smoothing, lies on the boundary of a voxel of B (within 1e-3 voxel): there the two
                unsmoothed surfaces meet. Its contact distance is the distance from the same vertex
                after smoothing to B's smoothed surface (exact point-to-triangle distance,
                vtkStaticCellLocator). The vertex is the same before and after smoothing: every
                smoother here moves vertices only (checked: the triangles are identical; segmesh's
                unsmoothed meshes come from a second run with --smooth none). Both directions
                (A to B, B to A) and every touching pair of the map are pooled: max and 95th
                percentile.
  crossings     triangles of one label's smoothed mesh that intersect a triangle of a touching
                label's smoothed mesh, counted on both sides: an edge of one mesh passes strictly
                through the inside of a triangle of the other (both end points more than 1e-6 mm
                off the triangle's plane, so triangles that share vertices or lie on each other do
                not count); the crossed triangle and the edge's triangles are counted once each.
                Every edge and triangle is tested (no subsampling), with a uniform grid to find
                the candidates.

All meshes are compared in segmesh's frame, world millimetres in LPS: VTK's index-millimetre
meshes go through the NIfTI affine (peer_mesh.to_world gives RAS) and x, y are negated. The check
printed under the table: most of VTK's unsmoothed vertices must coincide with segmesh's
unsmoothed independent ones (both are Marching Cubes on the same voxels), and it gives the
volume and volume centroid of all labels from both.

    conforming_vtk_table.py --segmesh BUILD/apps/cli/segmesh --out DIR MAP [MAP ...]

Needs Debian's python3-vtk9, python3-nibabel, python3-numpy and python3-scipy, and
../shared/tools/peer_mesh.py and mesh_metrics.py beside the repository.
"""
import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

import numpy as np
import vtk

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "shared" / "tools"))
import mesh_metrics  # noqa: E402
import peer_mesh  # noqa: E402

LPS_FROM_RAS = np.array([-1.0, -1.0, 1.0])
VTK = "VTK discrete FE + sinc"


# ----------------------------------------------------------------------------
# The three pipelines: {label: {"raw": (V, F), "smooth": (V, F)}} in LPS mm, plus per-part metrics
# ----------------------------------------------------------------------------

def segmesh_run(segmesh, path, out, extra, threads):
    """One `segmesh mesh` run into the folder `out`; returns its wall time."""
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    cmd = [segmesh, "mesh", path, "-o", out + "/", "--format", "ply", "--threads", str(threads),
           "--quiet"] + extra
    start = time.perf_counter()
    result = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit("segmesh failed: %s\n%s" % (" ".join(cmd), result.stderr))
    return wall


def segmesh_parts(folder):
    """{(label, component): (V, F)} from a per-part folder (files labelL_C.ply)."""
    parts = {}
    for name in sorted(os.listdir(folder)):
        match = re.fullmatch(r"label(\d+)_(\d+)\.ply", name)
        if not match:
            sys.exit("unexpected file %s in %s" % (name, folder))
        parts[(int(match[1]), int(match[2]))] = mesh_metrics.read_ply(os.path.join(folder, name))
    return parts


def merge(meshes):
    """Concatenate indexed meshes into one."""
    vs, fs, offset = [], [], 0
    for v, f in meshes:
        vs.append(v)
        fs.append(f + offset)
        offset += len(v)
    return np.concatenate(vs), np.concatenate(fs)


def segmesh_meshes(segmesh, path, out, extra, threads):
    """The smoothed parts in out/smooth (left by the timed runs) and, for the vertex
    correspondence, the same command with --smooth none, merged per label."""
    segmesh_run(segmesh, path, out + "/raw", extra + ["--smooth", "none"], threads)
    smooth, raw = segmesh_parts(out + "/smooth"), segmesh_parts(out + "/raw")
    if smooth.keys() != raw.keys() or any(not np.array_equal(smooth[k][1], raw[k][1]) for k in smooth):
        sys.exit("%s: the unsmoothed run gave other triangles; no vertex correspondence" % out)
    meshes = {}
    for label in sorted({k[0] for k in smooth}):
        keys = [k for k in smooth if k[0] == label]
        meshes[label] = {"raw": merge([raw[k] for k in keys]),
                         "smooth": merge([smooth[k] for k in keys])}
    return meshes, [mesh_metrics.compute_metrics(*m) for m in smooth.values()]


class VtkPipeline:
    """Slicer's conversion per label with peer_mesh.py's functions and default settings."""

    def __init__(self, path):
        data, self.spacing, self.affine = peer_mesh.load_volume(path)
        data = data.astype(np.int32)
        self.options = peer_mesh.parse_args([path])  # Slicer's: pass band 0.01, 20 iterations
        values = [int(v) for v in np.unique(data) if v != 0]
        self.images = {}
        for value, (lo, hi) in peer_mesh.label_boxes(data, values).items():  # untimed, as peer_mesh.py
            sub = peer_mesh.crop_pad(data, lo, hi, True, 0)
            self.images[value] = peer_mesh.to_vtk_image(sub, self.spacing,
                                                        (lo - 1) * np.asarray(self.spacing))

    def run(self):
        """One timed run of the two filters over every label: the wall time summed."""
        self.surfaces, wall = {}, 0.0
        for value, image in self.images.items():
            start = time.perf_counter()
            extract = peer_mesh.build_extractor("discrete_fe", image, None, value, None)
            extract.Update()
            smooth = peer_mesh.build_smoother("sinc", extract.GetOutput(), self.options)
            smooth.Update()
            wall += time.perf_counter() - start
            self.surfaces[value] = (extract.GetOutput(), smooth.GetOutput())
        return wall

    def meshes(self):
        """The last run's surfaces in LPS mm, and the metrics of each label's smoothed mesh."""
        meshes = {}
        for value, (raw_pd, smooth_pd) in self.surfaces.items():
            mesh = {}
            for key, pd in (("raw", raw_pd), ("smooth", smooth_pd)):
                v, f = peer_mesh.to_world(*peer_mesh.polydata_to_numpy(pd), self.spacing, self.affine)
                mesh[key] = (v * LPS_FROM_RAS, f)
            if not np.array_equal(mesh["raw"][1], mesh["smooth"][1]):
                sys.exit("VTK label %d: the smoother changed the triangles" % value)
            meshes[value] = mesh
        return meshes, [mesh_metrics.compute_metrics(*m["smooth"]) for m in meshes.values()]


def run_tools(segmesh, path, out, threads, repeats):
    """{tool: (best wall time, meshes per label, metrics per part)}. The three tools run in
    turn, `repeats` rounds, so that a change of the host's load hits all of them."""
    commands = {"segmesh conforming (default)": ("conforming", []),
                "segmesh independent": ("independent", ["--surfaces", "independent"])}
    vtk_run = VtkPipeline(path)
    vtk.vtkSMPTools.Initialize(threads)
    walls = {tool: float("inf") for tool in list(commands) + [VTK]}
    for _ in range(repeats):
        for tool, (folder, extra) in commands.items():
            walls[tool] = min(walls[tool], segmesh_run(segmesh, path, "%s/%s/smooth" % (out, folder),
                                                       extra, threads))
        walls[VTK] = min(walls[VTK], vtk_run.run())
    runs = {tool: (walls[tool],) + segmesh_meshes(segmesh, path, "%s/%s" % (out, folder), extra,
                                                  threads)
            for tool, (folder, extra) in commands.items()}
    runs[VTK] = (walls[VTK],) + vtk_run.meshes()
    return runs


# ----------------------------------------------------------------------------
# Contacts
# ----------------------------------------------------------------------------

def touching_pairs(labels):
    """Sorted label pairs (a < b) with a voxel of a sharing a face with a voxel of b."""
    base = np.int64(labels.max()) + 1
    keys = []
    for axis in range(3):
        a = np.moveaxis(labels, axis, 0)
        x, y = a[:-1], a[1:]
        m = (x != y) & (x > 0) & (y > 0)
        x, y = x[m].astype(np.int64), y[m].astype(np.int64)
        keys.append(np.unique(np.minimum(x, y) * base + np.maximum(x, y)))
    return [(int(k // base), int(k % base)) for k in np.unique(np.concatenate(keys))]


def to_index(v, affine):
    """LPS mm -> continuous voxel index."""
    return (v / LPS_FROM_RAS - affine[:3, 3]) @ np.linalg.inv(affine[:3, :3]).T


def on_voxel_of(labels, ijk, value, tol=1e-3):
    """Mask of the points lying on the closed box of a voxel labelled `value`."""
    lo = np.ceil(ijk - 0.5 - tol).astype(np.int64)
    hi = np.floor(ijk + 0.5 + tol).astype(np.int64)
    shape = np.array(labels.shape)
    hit = np.zeros(len(ijk), dtype=bool)
    for corner in np.ndindex(2, 2, 2):
        c = lo + corner
        ok = np.all((c <= hi) & (c >= 0) & (c < shape), axis=1)
        hit[ok] |= labels[c[ok, 0], c[ok, 1], c[ok, 2]] == value
    return hit


def distances_to(points, mesh):
    """Exact distance from each point to the triangle mesh (V, F)."""
    locator = vtk.vtkStaticCellLocator()
    locator.SetDataSet(peer_mesh.numpy_to_polydata(*mesh))
    locator.BuildLocator()
    closest, cell, sub, d2 = [0.0] * 3, vtk.reference(0), vtk.reference(0), vtk.reference(0.0)
    out = np.empty(len(points))
    for i, p in enumerate(points.tolist()):
        locator.FindClosestPoint(p, closest, cell, sub, d2)
        out[i] = d2.get()
    return np.sqrt(out)


def _cells(lo, hi, origin, size):
    """(cell key, item) for every grid cell each box [lo, hi] overlaps."""
    a = np.floor((lo - origin) / size).astype(np.int64)
    span = np.floor((hi - origin) / size).astype(np.int64) - a + 1
    n = span.prod(1)
    item = np.repeat(np.arange(len(lo)), n)
    rank = np.arange(len(item)) - np.repeat(np.cumsum(n) - n, n)
    sy, sz = span[item, 1], span[item, 2]
    c = a[item] + np.stack([rank // (sy * sz), rank // sz % sy, rank % sz], 1)
    return (c[:, 0] << 42) | (c[:, 1] << 21) | c[:, 2], item


def edges_through_triangles(va, fa, vb, fb, eps=1e-6):
    """Edges of mesh a passing strictly through triangles of mesh b.

    Returns (triangles of a that hold such an edge, crossed triangles of b)."""
    e = np.concatenate([fa[:, [0, 1]], fa[:, [1, 2]], fa[:, [2, 0]]])
    owner = np.tile(np.arange(len(fa)), 3)
    e = np.sort(e, 1)
    keys, edge_of = np.unique(e[:, 0] * len(va) + e[:, 1], return_inverse=True)
    edges = np.stack([keys // len(va), keys % len(va)], 1)
    seg, tri = va[edges], vb[fb]
    lo_e, hi_e, lo_t, hi_t = seg.min(1), seg.max(1), tri.min(1), tri.max(1)
    # Only what lies in both meshes' boxes can cross.
    box_lo, box_hi = np.maximum(lo_e.min(0), lo_t.min(0)), np.minimum(hi_e.max(0), hi_t.max(0))
    se = np.nonzero(np.all((hi_e >= box_lo) & (lo_e <= box_hi), 1))[0]
    st = np.nonzero(np.all((hi_t >= box_lo) & (lo_t <= box_hi), 1))[0]
    none = np.zeros(0, dtype=np.int64)
    if len(se) == 0 or len(st) == 0:
        return none, none
    # Cells twice the median triangle's extent (most boxes overlap one to eight cells), but at
    # least a quarter of the largest box's (none overlaps more than 5 x 5 x 5 cells).
    extent = np.concatenate([hi_t[st] - lo_t[st], hi_e[se] - lo_e[se]])
    size = np.maximum(np.maximum(2.0 * np.median(extent, axis=0), extent.max(0) / 4.0), 1e-3)
    origin = np.minimum(lo_e[se].min(0), lo_t[st].min(0))
    ekey, eitem = _cells(lo_e[se], hi_e[se], origin, size)
    tkey, titem = _cells(lo_t[st], hi_t[st], origin, size)
    order = np.argsort(tkey, kind="stable")
    tkey, titem = tkey[order], titem[order]
    order = np.argsort(eitem, kind="stable")  # an edge's cells together: pairs dedupe per chunk
    ekey, eitem = ekey[order], eitem[order]
    first, last = np.searchsorted(tkey, ekey, "left"), np.searchsorted(tkey, ekey, "right")
    count = last - first
    crossing_edges, crossed = [], []
    start = 0
    while start < len(ekey):
        stop = start + max(1, int(np.searchsorted(np.cumsum(count[start:]), 4_000_000)))
        while stop < len(ekey) and eitem[stop] == eitem[stop - 1]:
            stop += 1
        c = count[start:stop]
        n = int(c.sum())
        if n:
            rank = np.arange(n) - np.repeat(np.cumsum(c) - c, c)
            pe = se[np.repeat(eitem[start:stop], c)]
            pt = st[titem[np.repeat(first[start:stop], c) + rank]]
            pair = np.unique(pe * len(fb) + pt)
            pe, pt = pair // len(fb), pair % len(fb)
            hit = _segment_crosses_triangle(seg[pe], tri[pt], eps)
            crossing_edges.append(pe[hit])
            crossed.append(pt[hit])
        start = stop
    crossing_edges = np.concatenate(crossing_edges) if crossing_edges else none
    crossed = np.concatenate(crossed) if crossed else none
    holders = owner[np.isin(edge_of.ravel(), crossing_edges)]
    return np.unique(holders), np.unique(crossed)


def _segment_crosses_triangle(seg, tri, eps):
    p, q = seg[:, 0], seg[:, 1]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    length = np.linalg.norm(n, axis=1)
    ok = length > 0
    length[~ok] = 1.0
    dp = np.einsum("ij,ij->i", p - a, n) / length
    dq = np.einsum("ij,ij->i", q - a, n) / length
    ok &= (dp * dq < 0) & (np.abs(dp) > eps) & (np.abs(dq) > eps)
    d = q - p
    s1 = np.einsum("ij,ij->i", d, np.cross(a - p, b - p))
    s2 = np.einsum("ij,ij->i", d, np.cross(b - p, c - p))
    s3 = np.einsum("ij,ij->i", d, np.cross(c - p, a - p))
    return ok & (((s1 > 0) & (s2 > 0) & (s3 > 0)) | ((s1 < 0) & (s2 < 0) & (s3 < 0)))


def crossing_triangles(ma, mb):
    """Triangles of a and of b that intersect a triangle of the other mesh (both sides)."""
    a1, b1 = edges_through_triangles(*ma, *mb)
    b2, a2 = edges_through_triangles(*mb, *ma)
    return len(np.union1d(a1, a2)) + len(np.union1d(b1, b2))


def contact_quality(meshes, labels, affine, pairs):
    distances, crossings = [], 0
    for a, b in pairs:
        for p, q in ((a, b), (b, a)):
            raw_v = meshes[p]["raw"][0]
            on = on_voxel_of(labels, to_index(raw_v, affine), q)
            distances.append(distances_to(meshes[p]["smooth"][0][on], meshes[q]["smooth"]))
        crossings += crossing_triangles(meshes[a]["smooth"], meshes[b]["smooth"])
    d = np.concatenate(distances) if distances else np.zeros(0)
    return len(d), (d.max() if len(d) else 0.0), (np.percentile(d, 95) if len(d) else 0.0), crossings


# ----------------------------------------------------------------------------
# Scores
# ----------------------------------------------------------------------------

def volume_centroid(v, f):
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    six_vol = np.einsum("ij,ij->i", p0, np.cross(p1, p2))
    return six_vol.sum() / 6.0, (six_vol[:, None] * (p0 + p1 + p2)).sum(0) / (4.0 * six_vol.sum())


def volume_errors(meshes, labels, voxel_mm3):
    """Per label and for all labels together (%)."""
    counts = np.bincount(labels.ravel())
    mesh = np.array([abs(volume_centroid(*m["smooth"])[0]) for m in meshes.values()])
    voxels = np.array([counts[value] * voxel_mm3 for value in meshes])
    return 100.0 * (mesh / voxels - 1.0), 100.0 * (mesh.sum() / voxels.sum() - 1.0)


def frame_check(name, vtk_meshes, segmesh_meshes):
    """VTK's and segmesh's unsmoothed independent meshes share most vertices (the edge midpoints
    of Marching Cubes; the triangulations differ where the tools resolve ambiguous cubes
    differently) and their volumes and centroids agree: else the frames differ."""
    from scipy.spatial import cKDTree
    shared = total = 0
    sums = np.zeros((2, 4))
    for value, m in vtk_meshes.items():
        other = segmesh_meshes[value]["raw"]
        gap, _ = cKDTree(other[0]).query(m["raw"][0], distance_upper_bound=1e-3)
        shared += int(np.isfinite(gap).sum())
        total += len(gap)
        for row, mesh in enumerate((m["raw"], other)):
            volume, centroid = volume_centroid(*mesh)
            sums[row] += np.append(volume * centroid, volume)
    volumes = sums[:, 3]
    centroids = sums[:, :3] / volumes[:, None]
    line = ("%s: %.1f %% of VTK's unsmoothed vertices are segmesh's (to 1e-3 mm); all labels' "
            "volume %.4g vs %.4g mm3, centroid %s vs %s mm (%.3f mm apart)"
            % (name, 100.0 * shared / total, volumes[0], volumes[1],
               np.round(centroids[0], 2).tolist(), np.round(centroids[1], 2).tolist(),
               np.linalg.norm(centroids[0] - centroids[1])))
    if shared < 0.9 * total:
        sys.exit("frame check failed: " + line)
    return line


def is_closed(m):
    return m["closed"] and m["nonmanifold_vertices"] == 0 and m["orientation_errors"] == 0


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("maps", nargs="+")
    ap.add_argument("--segmesh", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)

    print("| map | tool | time (s) | / VTK | triangles | all parts closed, manifold | volume "
          "error %: median label / all | contact vertices | contact distance max (mm) | "
          "p95 (mm) | crossing triangles |")
    print("| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |", flush=True)
    described, checks = [], []
    for path in args.maps:
        name = os.path.basename(path)
        img = peer_mesh.nib.load(path)
        labels = np.asanyarray(img.dataobj).astype(np.int32)
        affine = img.affine
        spacing = [float(s) for s in img.header.get_zooms()[:3]]
        pairs = touching_pairs(labels)
        described.append("| %s | %s | %s | %d | %d |" % (
            name, " x ".join(map(str, labels.shape)), " x ".join("%.3g" % s for s in spacing),
            len(np.unique(labels)) - 1, len(pairs)))
        out = os.path.join(args.out, name.split(".")[0])
        runs = run_tools(args.segmesh, path, out, args.threads, args.repeats)
        checks.append(frame_check(name, runs[VTK][1],
                                  runs["segmesh independent"][1]))
        vtk_wall = runs[VTK][0]
        for tool, (wall, meshes, part_metrics) in runs.items():
            closed = sum(is_closed(m) for m in part_metrics)
            errors, together = volume_errors(meshes, labels, float(np.prod(spacing)))
            row = ["%s" % name, tool, "%.2f" % wall, "%.2f" % (wall / vtk_wall),
                   "%d" % sum(m["n_triangles"] for m in part_metrics),
                   "yes" if closed == len(part_metrics) else "%d of %d" % (closed, len(part_metrics)),
                   "%+.2f / %+.2f" % (np.median(errors), together)]
            if pairs:
                n, dmax, p95, crossings = contact_quality(meshes, labels, affine, pairs)
                row += ["%d" % n, "%.3f" % dmax, "%.3f" % p95, "%d" % crossings]
            else:
                row += ["-"] * 4
            print("| " + " | ".join(row) + " |", flush=True)
        del runs
    print()
    print("| map | voxels | spacing (mm) | labels | touching label pairs |")
    print("| --- | --- | --- | ---: | ---: |")
    print("\n".join(described))
    print()
    for line in checks:
        print("frame check, " + line)


if __name__ == "__main__":
    main(sys.argv[1:])
