"""What the Python tests share: the built CLI, the shared data and a PLY reader for its output."""

import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("SEGMESH_CLI", os.path.join(HERE, "..", "..", "build", "apps", "cli", "segmesh"))
DATA = os.environ.get("SEGMESH_SHARED_DATA", os.path.join(HERE, "..", "..", "..", "shared", "data"))


def data(*path):
    """A file of ../shared/data; skips the test (saying so) where it is absent."""
    p = os.path.join(DATA, *path)
    if not os.path.exists(p):
        raise unittest.SkipTest(f"{p} is absent (../shared/data is not beside the checkout)")
    return p


def run_cli(*args):
    """Runs the built `segmesh` program; returns its CompletedProcess (text), whatever its exit code."""
    if not os.path.exists(CLI):
        raise unittest.SkipTest(f"the segmesh program is not built ({CLI})")
    return subprocess.run([CLI, *args], capture_output=True, text=True)


def cli(*args):
    """Runs the built `segmesh` program; fails the test with its stderr when it fails."""
    done = run_cli(*args)
    if done.returncode != 0:
        raise AssertionError(f"segmesh {' '.join(args)} failed: {done.stderr}")
    return done


class TempDir:
    def __enter__(self):
        self.path = tempfile.mkdtemp(prefix="segmesh-python-")
        return self.path

    def __exit__(self, *exc):
        shutil.rmtree(self.path, ignore_errors=True)


_PLY_TYPES = {"float": "<f4", "uchar": "u1", "uint": "<u4", "int": "<i4"}


def read_ply(path):
    """The parts of a binary PLY written by segmesh: a list of (name, vertices, faces), each part's
    face indices relative to its own vertices (its ranges come from the header's part comments)."""
    with open(path, "rb") as f:
        raw = f.read()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode().splitlines()
    parts, props, n_vertices, n_faces, element = [], [], 0, 0, None
    for line in header:
        words = line.split()
        if line.startswith("comment part "):
            fields = dict(w.split("=", 1) for w in line[len("comment part "):].split(" name=")[0].split())
            parts.append((line.split(" name=", 1)[1], int(fields["vertices"]), int(fields["faces"])))
        elif words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                n_vertices = int(words[2])
            else:
                n_faces = int(words[2])
        elif words[:1] == ["property"] and element == "vertex":
            props.append((words[2], _PLY_TYPES[words[1]]))
    vertex = np.dtype(props)
    vertices = np.frombuffer(raw, vertex, n_vertices, end)
    xyz = np.stack([vertices["x"], vertices["y"], vertices["z"]], axis=1)
    face = np.dtype([("n", "u1"), ("i", "<u4", 3)])
    faces = np.frombuffer(raw, face, n_faces, end + vertex.itemsize * n_vertices)
    assert np.all(faces["n"] == 3)
    out, v0, f0 = [], 0, 0
    if not parts:
        parts = [("", n_vertices, n_faces)]
    for name, nv, nf in parts:
        out.append((name, xyz[v0:v0 + nv], faces["i"][f0:f0 + nf].astype(np.int64) - v0))
        v0, f0 = v0 + nv, f0 + nf
    return out


def cli_parts(volume, out_dir, *options):
    """`segmesh mesh volume -o out_dir/cli.ply [options]`, read back as read_ply's parts."""
    out = os.path.join(out_dir, "cli.ply")
    cli("mesh", volume, "-o", out, "--quiet", *options)
    return read_ply(out)


def max_vertex_difference(test, parts, reference):
    """Asserts that `parts` (segmesh.Part) are `reference` (read_ply's) part for part: same names,
    same faces, and returns the largest vertex coordinate difference in mm."""
    test.assertEqual([p.name for p in parts], [name for name, _, _ in reference])
    worst = 0.0
    for p, (name, vertices, faces) in zip(parts, reference):
        test.assertEqual(p.vertices.shape, vertices.shape, name)
        np.testing.assert_array_equal(p.faces, faces, err_msg=name)
        worst = max(worst, float(np.max(np.abs(p.vertices - vertices))) if len(vertices) else 0.0)
    return worst
