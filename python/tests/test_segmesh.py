"""segmesh.mesh on arrays: memory orders and dtypes, the options layer, the errors, progress,
cancellation and the GIL."""

import _thread
import signal
import sys
import threading
import time
import unittest

import numpy as np

import segmesh


def two_boxes(dtype=np.uint8, order="C"):
    labels = np.zeros((24, 20, 16), dtype, order=order)
    labels[2:10, 3:15, 2:12] = 1
    labels[10:20, 3:15, 2:12] = 2  # touches label 1: one contact
    return labels


class Arrays(unittest.TestCase):
    def test_parts_and_their_fields(self):
        parts = segmesh.mesh(two_boxes(), spacing=(0.5, 0.7, 1.2), origin=(10, 20, 30))
        self.assertIsInstance(parts, list)
        self.assertEqual([(p.name, p.label, p.role) for p in parts],
                         [("label1_1", 1, "bone"), ("label2_1", 2, "implant")])
        for p in parts:
            self.assertEqual(p.vertices.dtype, np.float32)
            self.assertEqual(p.vertices.shape[1], 3)
            self.assertEqual(p.faces.dtype, np.int32)
            self.assertEqual(p.faces.shape[1], 3)
            self.assertEqual(p.normals.shape, p.vertices.shape)
            self.assertTrue(p.measures["closed"])
            self.assertEqual(p.measures["triangles"], len(p.faces))
            self.assertGreater(p.measures["quality"]["min"], 0)
            self.assertIn("hausdorff_mm", p.measures["smoothing_deviation"])
        # Smoothing restores the volume: close to the voxels' own volume.
        self.assertAlmostEqual(parts[0].measures["volume_mm3"], 8 * 12 * 10 * 0.5 * 0.7 * 1.2,
                               delta=0.05 * 8 * 12 * 10 * 0.5 * 0.7 * 1.2)
        self.assertEqual(len(parts.contacts), 1)
        contact = parts.contacts[0]
        self.assertIs(contact["a"], parts[0])
        self.assertIs(contact["b"], parts[1])
        self.assertGreater(contact["area_mm2"], 0)
        self.assertLess(contact["max_gap_mm"], 1e-4)

    def test_world_placement(self):
        # Voxel (i, j, k) at origin + direction @ (spacing * (i, j, k)), LPS.
        labels = np.zeros((10, 10, 10), np.uint8)
        labels[2:6, 2:6, 2:6] = 1  # centre 3.5 in every axis
        d = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], float)
        spacing = np.array([0.5, 2.0, 3.0])
        origin = np.array([-5.0, 4.0, 100.0])
        p = segmesh.mesh(labels, spacing=spacing, origin=origin, direction=d,
                         smooth="none")[0]
        expected = origin + d @ (spacing * 3.5)
        np.testing.assert_allclose(p.vertices.mean(axis=0), expected, atol=1e-4)
        lo, hi = p.vertices.min(axis=0), p.vertices.max(axis=0)
        # Marching Cubes of a 4-voxel box spans 4 voxels (edge midpoints): 2, 8, 12 mm along i, j, k.
        np.testing.assert_allclose(np.sort(hi - lo), np.sort(np.abs(d) @ (spacing * 4)), atol=1e-4)

    def test_memory_order_and_dtype_do_not_change_the_mesh(self):
        reference = segmesh.mesh(two_boxes(), measure=False)
        for dtype in (np.uint8, np.uint16, np.int16, np.int32, np.int8, bool):
            for order in ("C", "F"):
                labels = two_boxes(np.uint8 if dtype is bool else dtype, order)
                expected = reference
                if dtype is bool:
                    labels = labels == 1
                    expected = segmesh.mesh((labels).astype(np.uint8), measure=False)
                parts = segmesh.mesh(labels, measure=False)
                np.testing.assert_array_equal(parts[0].vertices, expected[0].vertices,
                                              err_msg=f"{np.dtype(dtype)} {order}")
        # A strided view (every other voxel along i) is a volume of its own.
        view = np.repeat(two_boxes(), 2, axis=0)[::2]
        np.testing.assert_array_equal(segmesh.mesh(view, measure=False)[0].vertices,
                                      reference[0].vertices)

    def test_input_not_kept_and_output_not_copied(self):
        # The input array is read (one copy into the core's volume: a memcpy for Fortran order)
        # and not kept; the meshes come back as arrays over the core's own buffers.
        labels = np.asfortranarray(two_boxes())
        before = sys.getrefcount(labels)
        parts = segmesh.mesh(labels, measure=False)
        self.assertEqual(sys.getrefcount(labels), before)
        for p in parts:
            self.assertFalse(p.vertices.flags.owndata)
            self.assertFalse(p.faces.flags.owndata)

    def test_options_are_the_clis(self):
        specs = {s["keyword"]: s for s in segmesh.options()}
        self.assertIn("taubin_lambda", specs)
        self.assertEqual(specs["connectivity"]["name"], "connectivity")
        labels = two_boxes()
        dc = segmesh.mesh(labels, method="dc", measure=False)
        mc = segmesh.mesh(labels, measure=False)
        self.assertNotEqual(len(dc[0].vertices), len(mc[0].vertices))
        only2 = segmesh.mesh(labels, labels=[2], measure=False)
        self.assertEqual([p.label for p in only2], [2])
        colored = segmesh.mesh(labels, color="quality", measure=False)
        self.assertEqual(colored[0].colors.shape, (len(colored[0].vertices), 4))
        named = segmesh.mesh(labels, label_names={1: "tibia", 2: ("plate", "implant")},
                             measure=False)
        self.assertEqual([(p.name, p.role) for p in named], [("tibia_1", "other"),
                                                             ("plate_1", "implant")])

    def test_float_volume_with_iso(self):
        x, y, z = np.mgrid[-10:11, -10:11, -10:11].astype(np.float32)
        ball = 8.0 - np.sqrt(x * x + y * y + z * z)
        parts = segmesh.mesh(ball, iso=0.0, smooth="none")
        self.assertEqual(len(parts), 1)
        r = np.linalg.norm(parts[0].vertices - parts[0].vertices.mean(axis=0), axis=1)
        self.assertLess(np.max(np.abs(r - 8.0)), 0.1)


class Errors(unittest.TestCase):
    def assertValueError(self, pattern, *args, **kwargs):
        with self.assertRaisesRegex(ValueError, pattern):
            segmesh.mesh(*args, **kwargs)

    def test_bad_arrays(self):
        self.assertValueError(r"4-D images are not supported \(dims 2x3x4x5\)",
                              np.ones((2, 3, 4, 5), np.uint8))
        self.assertValueError(r"2-D images are not supported", np.ones((3, 4), np.uint8))
        self.assertValueError(r"array: empty \(shape 0x4x4\)", np.ones((0, 4, 4), np.uint8))
        self.assertValueError(r"float64 values are not labels; give --iso",
                              np.ones((4, 4, 4)))
        self.assertValueError(r"dtype int64 is not supported", np.ones((4, 4, 4), np.int64))
        self.assertValueError(r"dtype complex128 is not supported", np.ones((4, 4, 4), complex))
        self.assertValueError(r"expected a numpy array, got list", [[[1]]])
        self.assertValueError(r"no foreground: every voxel is 0", np.zeros((4, 4, 4), np.uint8))
        self.assertValueError(r"spacing", np.ones((4, 4, 4), np.uint8), spacing=(1, 0, 1))
        self.assertValueError(r"direction matrix\) is not a rotation",
                              np.ones((4, 4, 4), np.uint8), direction=np.ones((3, 3)))
        self.assertValueError(r"either affine= or spacing=", np.ones((4, 4, 4), np.uint8),
                              spacing=1, affine=np.eye(4))

    def test_bad_options(self):
        labels = two_boxes()
        self.assertValueError(r"--connectivity must be 6, 18 or 26", labels, connectivity=7)
        self.assertValueError(r"unknown option conectivity", labels, conectivity=6)
        self.assertValueError(r"--method", labels, method="spline")
        self.assertValueError(r"--labels", labels, labels="one")
        self.assertValueError(r"label 7 .*not", labels, labels=[7])
        self.assertValueError(r"--color must be material or quality", labels, color="red")
        self.assertValueError(r"--threads must be 0", labels, threads=-1)
        self.assertValueError(r"unknown role", labels, label_names={1: ("a", "bonez")})
        for bad in (5, {1: 5}, {"a": "b"}):
            self.assertValueError(r"label_names must be a TSV file", labels, label_names=bad)
        with self.assertRaisesRegex(TypeError, r"progress must be a callable"):
            segmesh.mesh(labels, progress=5)
        with self.assertRaisesRegex(ValueError, r"nothing\.tsv"):
            segmesh.mesh(labels, label_names="nothing.tsv")
        with self.assertRaisesRegex(ValueError, r"missing\.nii\.gz"):
            segmesh.mesh_file("missing.nii.gz")


class ProgressAndCancel(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # Large enough that meshing takes a second or more on two cores.
        cls.labels, cls.spacing = segmesh.phantom(size=(384, 384, 160))

    def test_progress_reports_steps(self):
        seen = []
        segmesh.mesh(self.labels, spacing=self.spacing, measure=False,
                     progress=lambda step, fraction: seen.append((step, fraction)))
        steps = [s for s, _ in seen]
        self.assertIn("components", steps)
        self.assertIn("marching cubes", steps)
        self.assertIn("smoothing", steps)
        self.assertTrue(all(0 <= f <= 1 for _, f in seen))

    def test_short_run_reports_every_step(self):
        seen = []
        segmesh.mesh(two_boxes(), measure=False, progress=lambda s, f: seen.append((s, f)))
        steps = [s for i, (s, _) in enumerate(seen) if i == 0 or seen[i - 1][0] != s]
        self.assertEqual(steps, ["components", "marching cubes", "smoothing"])
        self.assertEqual(seen[-1], ("smoothing", 1))

    def test_callback_result_without_truth_value_raises(self):
        with self.assertRaisesRegex(ValueError, "truth value"):
            segmesh.mesh(self.labels, spacing=self.spacing,
                         progress=lambda s, f: np.array([1, 2]))

    def test_callback_returning_false_cancels(self):
        calls = []

        def stop(step, fraction):
            calls.append(step)
            return step != "marching cubes"

        with self.assertRaises(segmesh.Cancelled):
            segmesh.mesh(self.labels, spacing=self.spacing, progress=stop)
        self.assertEqual(calls[-1], "marching cubes")

    def test_callback_exception_cancels_and_is_raised(self):
        def fail(step, fraction):
            raise RuntimeError("stop here")

        with self.assertRaisesRegex(RuntimeError, "stop here"):
            segmesh.mesh(self.labels, spacing=self.spacing, progress=fail)

    def test_keyboard_interrupt_cancels(self):
        start = time.monotonic()
        segmesh.mesh(self.labels, spacing=self.spacing)
        full = time.monotonic() - start
        # A process started in the background by a non-interactive shell inherits SIGINT ignored,
        # and Python then leaves it so (interrupt_main does nothing): Python's own handler, as in
        # an interactive session, for the length of the test.
        previous = signal.signal(signal.SIGINT, signal.default_int_handler)
        self.addCleanup(signal.signal, signal.SIGINT, previous)
        timer = threading.Timer(0.2, _thread.interrupt_main)
        start = time.monotonic()
        timer.start()
        with self.assertRaises(KeyboardInterrupt):
            segmesh.mesh(self.labels, spacing=self.spacing)
        stopped = time.monotonic() - start
        timer.join()
        self.assertLess(stopped, 0.2 + max(0.5, full / 2), f"a full run takes {full:.2f} s")

    def test_gil_released_while_meshing(self):
        ticks = [0]
        done = threading.Event()

        def count():
            while not done.is_set():
                ticks[0] += 1
                time.sleep(0.001)

        counter = threading.Thread(target=count)
        counter.start()
        start = time.monotonic()
        segmesh.mesh(self.labels, spacing=self.spacing, measure=False)
        elapsed = time.monotonic() - start
        done.set()
        counter.join()
        # A thread holding the GIL for the whole run would leave the counter near 0.
        self.assertGreater(ticks[0], 0.2 * elapsed / 0.001 * 0.5, f"{ticks[0]} ticks in {elapsed:.2f} s")


class Integrations(unittest.TestCase):
    def test_to_trimesh(self):
        try:
            import trimesh  # noqa: F401
        except ImportError:
            self.skipTest("trimesh is not installed (not packaged in Debian 12): to_trimesh() untested")
        p = segmesh.mesh(two_boxes(), measure=False)[0]
        self.assertTrue(p.to_trimesh().is_watertight)

    def test_to_pyvista(self):
        try:
            import pyvista  # noqa: F401
        except ImportError:
            self.skipTest("pyvista is not installed (not packaged in Debian 12): to_pyvista() untested")
        p = segmesh.mesh(two_boxes(), measure=False)[0]
        self.assertEqual(p.to_pyvista().n_cells, len(p.faces))

    def test_without_the_packages_the_error_says_what_to_install(self):
        p = segmesh.mesh(two_boxes(), measure=False)[0]
        for method, package in (("to_trimesh", "trimesh"), ("to_pyvista", "pyvista")):
            try:
                __import__(package)
                continue
            except ImportError:
                pass
            with self.assertRaisesRegex(ImportError, package):
                getattr(p, method)()


if __name__ == "__main__":
    unittest.main()
