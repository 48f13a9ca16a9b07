"""segmesh: watertight surface meshes from segmented CT label maps (docs/PYTHON.md).

    import nibabel as nib, segmesh
    parts = segmesh.mesh(nib.load("seg.nii.gz"))          # or mesh(array, spacing=..., ...)
    for p in parts:
        print(p.name, p.vertices.shape, p.measures["volume_mm3"], p.measures["closed"])
    segmesh.write(parts, "scene.glb")

Axis order: an array is indexed labels[i, j, k] as nibabel indexes it, i the fastest axis of
segmesh's (and the file's) voxel order. Voxel (i, j, k) sits at
origin + direction @ (spacing * (i, j, k)) in world millimetres, LPS (ITK, DICOM, 3D Slicer);
`affine=` takes a 4x4 voxel-to-RAS matrix as nibabel gives it and converts it to LPS. A
Fortran-ordered array is copied with one memcpy; any other layout with one strided copy.

Options are `segmesh mesh`'s, by the same names with underscores for dashes and with the same
defaults and checks (segmesh.options() lists them): mesh(a, method="dc", iterations=30,
labels=[1, 2], iso=300, pass_band=0.02). A flag takes True or False: preserve_volume=False is the
CLI's --no-preserve-volume. A bad option or array raises ValueError with the CLI's message.

Cohorts: segmesh.run_case(file, "out") is one case of `segmesh batch` (segmesh/cases.py).
"""

import os as _os

import numpy as _np

from . import _segmesh
from ._segmesh import Cancelled
from .cases import Cohort, cohort, run_case, summary_file_name, write_summary

__all__ = ["mesh", "mesh_file", "write", "options", "phantom", "Part", "Result", "Cancelled",
           "lps_grid_from_ras_affine", "run_case", "cohort", "Cohort", "write_summary",
           "summary_file_name"]

# RAS (nibabel, NIfTI) to LPS (ITK, DICOM, segmesh): x and y change sign.
_RAS_TO_LPS = _np.diag([-1.0, -1.0, 1.0, 1.0])


class Part:
    """One meshed part: a connected component of one label (or of an iso-surface).

    name, label, component, role ("bone", "implant", "other"), vertices (N x 3 float32, world mm,
    LPS), faces (M x 3 int32, counter-clockwise seen from outside), normals (N x 3 float32),
    colors (N x 4 uint8, with color="quality"), voxels, voxel_volume_mm3, color/metallic/roughness
    (its material) and measures: the report's numbers (measure_scene) -- volume_mm3, area_mm2,
    closed, quality {min, mean, p01, histogram}, volume_before_smoothing_mm3,
    smoothing_deviation {hausdorff_mm, mean_mm, p95_mm}, and the topology counts.
    """

    def __init__(self, fields):
        self.__dict__.update(fields)
        self.__dict__.setdefault("measures", {})

    def __repr__(self):
        return (f"Part({self.name!r}, label={self.label}, role={self.role!r}, "
                f"vertices={len(self.vertices)}, faces={len(self.faces)})")

    def _fields(self):
        return dict(self.__dict__)

    def to_trimesh(self):
        """The part as a trimesh.Trimesh (needs the trimesh package)."""
        try:
            import trimesh
        except ImportError as e:
            raise ImportError("to_trimesh() needs the trimesh package (pip install trimesh)") from e
        return trimesh.Trimesh(vertices=self.vertices, faces=self.faces,
                               vertex_normals=self.normals, process=False)

    def to_pyvista(self):
        """The part as a pyvista.PolyData (needs the pyvista package)."""
        try:
            import pyvista
        except ImportError as e:
            raise ImportError("to_pyvista() needs the pyvista package (pip install pyvista)") from e
        cells = _np.hstack([_np.full((len(self.faces), 1), 3, _np.int64),
                            self.faces.astype(_np.int64)]).ravel()
        poly = pyvista.PolyData(self.vertices, cells)
        if len(self.normals):
            poly.point_data["Normals"] = self.normals
        return poly


class Result(list):
    """The parts of one run (a list of Part) plus what concerns them together.

    contacts: with conforming surfaces, every pair of touching parts as a dict
    (a, b: the two Parts; area_mm2; max_gap_mm, 0 to float rounding when both shells share the
    contact). conforming, dropped_components, timings (ms), warnings (the reader's).
    """

    def __init__(self, raw):
        super().__init__(Part(p) for p in raw["parts"])
        self.contacts = [dict(c, a=self[c["a"]], b=self[c["b"]]) for c in raw["contacts"]]
        self.conforming = raw["conforming"]
        self.dropped_components = raw["dropped_components"]
        self.timings = raw["timings"]
        self.warnings = raw.get("warnings", [])

    def part(self, name):
        """The part named `name` (KeyError if there is none)."""
        for p in self:
            if p.name == name:
                return p
        raise KeyError(name)


def options():
    """segmesh mesh's options: dicts of name (CLI), keyword, type, help and default (as text)."""
    return _segmesh.option_specs()


def lps_grid_from_ras_affine(affine):
    """(spacing, origin, direction) in LPS of a 4x4 voxel-to-RAS affine (nibabel's img.affine)."""
    a = _np.asarray(affine, dtype=_np.float64)
    if a.shape != (4, 4):
        raise ValueError(f"affine must be a 4x4 matrix (got shape {a.shape})")
    lps = _RAS_TO_LPS @ a
    spacing = _np.linalg.norm(lps[:3, :3], axis=0)
    if not _np.all(spacing > 0):
        raise ValueError("affine: a voxel axis has zero length; the affine is degenerate")
    direction = lps[:3, :3] / spacing
    return tuple(spacing), tuple(lps[:3, 3]), tuple(direction.ravel())


def _is_nibabel_image(obj):
    return hasattr(obj, "affine") and hasattr(obj, "dataobj")


def _geometry(spacing, origin, direction, affine):
    if affine is not None:
        if spacing is not None or origin is not None or direction is not None:
            raise ValueError("give either affine= or spacing=/origin=/direction=, not both")
        return lps_grid_from_ras_affine(affine)
    spacing = (1.0, 1.0, 1.0) if spacing is None else spacing
    spacing = (float(spacing),) * 3 if _np.isscalar(spacing) else tuple(float(s) for s in spacing)
    origin = (0.0, 0.0, 0.0) if origin is None else tuple(float(o) for o in origin)
    d = _np.eye(3) if direction is None else _np.asarray(direction, dtype=_np.float64)
    if len(spacing) != 3 or len(origin) != 3 or d.size != 9:
        raise ValueError("spacing and origin take three numbers, direction a 3x3 matrix")
    return spacing, origin, tuple(d.reshape(9))


def _check_progress(progress):
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable(step, fraction), not {type(progress).__name__}")


def mesh(labels, /, spacing=None, origin=None, direction=None, affine=None, *, label_names=None,
         color="material", measure=True, progress=None, threads=0, max_voxels=2_000_000_000,
         **options):
    """Meshes a label map (or, with iso=, a grey-value volume) held in memory.

    labels: a 3-D numpy array indexed [i, j, k] (uint8, uint16, int16 or int32 labels; bool and
    int8 are widened; float32/float64 need iso=), or a nibabel image (its data and its RAS affine).
    spacing (mm), origin (mm) and direction (3x3, columns the world directions of i, j, k) are LPS,
    as segmesh's files and the CLI report them; affine= is a 4x4 voxel-to-RAS matrix (nibabel).
    label_names: a TSV file (the CLI's --label-names) or a dict {label: name or (name, role)}.
    progress: callable(step, fraction), called from the calling thread about twenty times a second
    and at least once per step; returning False cancels (segmesh.Cancelled is raised), and so
    does an exception it raises (raised again) or Ctrl-C (KeyboardInterrupt). measure=False skips the report's numbers (Part.measures, contacts).
    `labels` is positional-only, so labels=[1, 2] is the CLI's --labels option.
    Returns a Result, a list of Part.
    """
    if _is_nibabel_image(labels):
        if affine is None and spacing is None and origin is None and direction is None:
            affine = labels.affine
        labels = _np.asanyarray(labels.dataobj)
    spacing, origin, direction = _geometry(spacing, origin, direction, affine)
    _check_progress(progress)
    return Result(_segmesh.mesh_array(labels, spacing, origin, direction, label_names, color,
                                      measure, progress, threads, max_voxels, options))


def mesh_file(path, /, *, label_names=None, color="material", measure=True, progress=None, threads=0,
              max_voxels=2_000_000_000, **options):
    """Meshes a volume file (every format `segmesh mesh` reads: .nii[.gz], .nrrd, .seg.nrrd,
    .nhdr, .mha, .mhd, .mrc/.map/.rec, a DICOM SEG file, a DICOM folder) as `segmesh mesh`
    would. The reader's warnings are in Result.warnings. Otherwise as mesh()."""
    _check_progress(progress)
    return Result(_segmesh.mesh_file(_os.fspath(path), label_names, color, measure, progress,
                                     threads, max_voxels, options))


def write(parts, path, format=None, quantize=False):
    """Writes parts (a Result, a list of Part or of dicts with Part's fields, or one Part) to `path`: .stl, .ply, .obj (+ .mtl) or
    .glb by its extension, all parts in one file; or, when `path` ends with "/" or is a folder,
    one file per part named after it (format= "stl", "ply" (default), "obj" or "glb"), as
    `segmesh mesh -o` does. quantize=True: a compact GLB (KHR_mesh_quantization), as
    `segmesh mesh --quantize`. Returns the files written."""
    if isinstance(parts, Part):
        parts = [parts]
    fields = [p._fields() if isinstance(p, Part) else dict(p) for p in parts]
    return _segmesh.write(fields, _os.fspath(path), format or "", bool(quantize))


def phantom(size=(512, 512, 203), spacing=(0.197, 0.197, 2.0)):
    """The built-in phantom (`segmesh phantom`: tibia and fibula 1, plate and screws 2) as
    (labels, spacing): a Fortran-ordered int32 array indexed [i, j, k] and its LPS spacing."""
    return _segmesh.phantom(tuple(size), tuple(spacing))
