"""segmesh.mesh and segmesh.mesh_file against `segmesh mesh` on the same volumes: the same parts,
the same triangles and the same vertices (to float rounding) in the same world coordinates."""

import os
import unittest

import numpy as np

import segmesh
from support import TempDir, cli_parts, data, max_vertex_difference, read_ply

try:
    import nibabel
except ImportError:  # Debian: python3-nibabel (scripts/install-deps.sh)
    nibabel = None

# Vertices are float32 world millimetres; the grid comes from the same header through nibabel
# (float64 from the float32 sform) or ITK, so the coordinates agree to a few float32 ulps.
TOLERANCE_MM = 1e-3


@unittest.skipIf(nibabel is None, "nibabel is not installed (Debian: python3-nibabel)")
class NibabelAgainstCli(unittest.TestCase):
    def check_file(self, *path):
        volume = data(*path)
        image = nibabel.load(volume)
        with TempDir() as tmp:
            reference = cli_parts(volume, tmp)
        parts = segmesh.mesh(image)
        worst = max_vertex_difference(self, parts, reference)
        self.assertLess(worst, TOLERANCE_MM)
        return parts

    def test_ras_file_same_vertices_as_cli(self):
        parts = self.check_file("totalsegmentator", "example_seg.nii.gz")
        self.assertGreater(len(parts), 20)
        for p in parts:
            self.assertTrue(p.measures["closed"], p.name)
            self.assertGreater(p.measures["volume_mm3"], 0, p.name)

    def test_las_anisotropic_file_same_vertices_as_cli(self):
        # LAS affine (one axis mirrored relative to RAS), 0.977 x 0.977 x 2 mm.
        self.check_file("totalsegmentator", "example_seg_dicom.nii.gz")

    def test_plain_array_with_the_affine_is_the_image(self):
        image = nibabel.load(data("totalsegmentator", "example_seg.nii.gz"))
        array = np.asarray(image.dataobj)
        a = segmesh.mesh(array, affine=image.affine, measure=False)
        b = segmesh.mesh(image, measure=False)
        for p, q in zip(a, b):
            np.testing.assert_array_equal(p.vertices, q.vertices)

    def test_axis_order_is_nibabels(self):
        # One block of voxels at a known index [i, j, k] of an anisotropic, shifted, rotated grid:
        # the mesh must sit around that voxel's world position (nibabel's affine, RAS -> LPS), and
        # be the CLI's mesh of the same array written by nibabel.
        labels = np.zeros((20, 16, 12), np.uint8)
        labels[3:7, 9:12, 2:5] = 1  # centre (4.5, 10, 3)
        c, s = np.cos(0.3), np.sin(0.3)
        affine = np.array([[c * 0.8, -s * 1.1, 0, 12.0],
                           [s * 0.8, c * 1.1, 0, -30.0],
                           [0, 0, 2.5, 7.0],
                           [0, 0, 0, 1]])
        parts = segmesh.mesh(labels, affine=affine, smooth="none")
        self.assertEqual(len(parts), 1)
        ras = affine @ np.array([4.5, 10.0, 3.0, 1.0])
        lps = np.array([-ras[0], -ras[1], ras[2]])
        np.testing.assert_allclose(parts[0].vertices.mean(axis=0), lps, atol=0.05)
        with TempDir() as tmp:
            path = os.path.join(tmp, "block.nii.gz")
            nibabel.save(nibabel.Nifti1Image(labels, affine), path)
            reference = cli_parts(path, tmp, "--smooth", "none")
            self.assertLess(max_vertex_difference(self, parts, reference), TOLERANCE_MM)
            from_file = segmesh.mesh_file(path, smooth="none")
        # The file stores the affine in float32: the same vertices to float rounding.
        np.testing.assert_allclose(from_file[0].vertices, parts[0].vertices, rtol=0, atol=1e-4)


class FilesAgainstCli(unittest.TestCase):
    """mesh_file on every format the CLI reads: the CLI's parts exactly."""

    def check(self, path, *options, **kwargs):
        with TempDir() as tmp:
            reference = cli_parts(path, tmp, *options)
        parts = segmesh.mesh_file(path, **kwargs)
        self.assertEqual(max_vertex_difference(self, parts, reference), 0.0)
        return parts

    def test_nifti(self):
        self.check(data("totalsegmentator", "example_seg.nii.gz"))

    def test_nrrd(self):
        parts = self.check(data("dcmqi", "liver_spine_seg.nrrd"))
        self.assertEqual(sorted({p.label for p in parts}), [1, 2])

    def test_dicom_series_with_iso(self):
        self.check(data("slicer_ct_head", "CTHeadAxialDicom"), "--iso", "1150", iso=1150)

    def test_mrc_with_iso(self):
        self.check(data("mrc", "EMD-3197.map"), "--iso", "0.5", iso=0.5)

    def test_metaimage_and_options(self):
        with TempDir() as tmp:
            path = os.path.join(tmp, "phantom.mha")
            from support import cli
            cli("phantom", "-o", path, "--size", "64,64,40", "--spacing", "0.8,0.8,1.5", "--quiet")
            self.check(path, "--method", "dc", "--iterations", "5", method="dc",
                       iterations=5)

    def test_label_names_tsv(self):
        names = data("totalsegmentator", "labels.tsv")
        parts = self.check(data("totalsegmentator", "example_seg.nii.gz"), "--label-names", names,
                           label_names=names)
        self.assertIn("vertebrae_L2_1", [p.name for p in parts])
        self.assertEqual(parts.part("vertebrae_L2_1").role, "bone")


class WriteFormats(unittest.TestCase):
    def test_every_format_the_cli_writes(self):
        parts = segmesh.mesh_file(data("dcmqi", "liver_spine_seg.nrrd"))
        with TempDir() as tmp:
            for ext in ("stl", "ply", "obj", "glb"):
                path = os.path.join(tmp, "scene." + ext)
                self.assertEqual(segmesh.write(parts, path), [path])
                self.assertGreater(os.path.getsize(path), 1000, ext)
            self.assertTrue(os.path.exists(os.path.join(tmp, "scene.mtl")))
            # The PLY holds the parts as they are, and `segmesh quality` reads what was written.
            back = read_ply(os.path.join(tmp, "scene.ply"))
            self.assertEqual(max_vertex_difference(self, parts, back), 0.0)
            files = segmesh.write(parts, os.path.join(tmp, "parts") + "/", format="stl")
            self.assertEqual(len(files), len(parts))
            with self.assertRaisesRegex(ValueError, "unknown mesh format"):
                segmesh.write(parts, os.path.join(tmp, "scene.xyz"))
            # quantize=True: the CLI's --quantize, a smaller GLB; refused for other formats.
            small = os.path.join(tmp, "small.glb")
            self.assertEqual(segmesh.write(parts, small, quantize=True), [small])
            self.assertLess(os.path.getsize(small), 0.8 * os.path.getsize(os.path.join(tmp, "scene.glb")))
            with self.assertRaisesRegex(ValueError, "--quantize .* needs glb output, not ply"):
                segmesh.write(parts, os.path.join(tmp, "small.ply"), quantize=True)
            self.assertFalse(os.path.exists(os.path.join(tmp, "small.ply")))


if __name__ == "__main__":
    unittest.main()
