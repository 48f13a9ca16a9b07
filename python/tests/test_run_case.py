"""segmesh.run_case against `segmesh batch` (issue 38): the same summary row and the same
report.json (except timings) for the same file, the CLI's messages for a corrupt and a missing
file, manifest cells applied as the CLI applies them, finished cases skipped, stale temporary
folders of the case removed and another case's never."""

import csv
import json
import os
import threading
import unittest

import segmesh
from support import TempDir, data, run_cli

# What differs between two runs of the same case: the wall time.
TIMES = ("seconds",)


def read_summary(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def without(row, keys=TIMES):
    return {k: v for k, v in row.items() if k not in keys}


def report(folder, out_dir):
    """report.json with its timings left out and OUT written as "OUT"."""
    with open(os.path.join(folder, "report.json")) as f:
        text = f.read()
    r = json.loads(text.replace(out_dir, "OUT"))
    r.pop("timings_ms")
    return r


def hidden(out_dir):
    return sorted(e for e in os.listdir(out_dir) if e.startswith("."))


class RunCaseAgainstCli(unittest.TestCase):
    def test_rows_reports_and_failures_are_the_clis(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        spine = data("dcmqi", "spine_seg.nrrd")
        with TempDir() as tmp:
            corrupt = os.path.join(tmp, "corrupt.nrrd")
            with open(corrupt, "w") as f:
                f.write("not a volume at all, only text pretending to be NRRD\n")
            missing = os.path.join(tmp, "missing.nii.gz")
            # A manifest: per-case cells over the command line's values.
            manifest = os.path.join(tmp, "cohort.csv")
            with open(manifest, "w") as f:
                f.write(f"path,case,iterations\n{heart},heart,\n{spine},spine,7\n{corrupt},,\n"
                        f"{missing},,\n")
            cli_out, py_out = os.path.join(tmp, "cli"), os.path.join(tmp, "py")
            done = run_cli("batch", manifest, "-o", cli_out, "--quiet", "--smooth", "taubin")
            self.assertEqual(done.returncode, 1, done.stderr)
            expected = read_summary(os.path.join(cli_out, "summary.csv"))

            cases = segmesh.cohort(manifest, py_out, smooth="taubin")
            self.assertEqual(len(cases), 4)
            self.assertEqual(cases.total, 4)
            self.assertFalse(os.path.exists(py_out))  # cohort() writes nothing
            rows = [segmesh.run_case(c, py_out, smooth="taubin") for c in cases]
            for row in rows:
                self.assertEqual(row.pop("warnings"), [])
            segmesh.write_summary(os.path.join(py_out, segmesh.summary_file_name()), rows)
            got = read_summary(os.path.join(py_out, "summary.csv"))
            self.assertEqual([without(r) for r in got], [without(r) for r in expected])
            self.assertEqual([r["status"] for r in got], ["ok", "ok", "failed", "failed"])
            self.assertIn("corrupt.nrrd: not a NRRD file", got[2]["error"])
            self.assertIn("missing.nii.gz: no such file", got[3]["error"])
            # The numbers of the dicts are the summary's, to its precision.
            self.assertEqual(rows[0]["triangles"], int(expected[0]["triangles"]))
            self.assertAlmostEqual(rows[0]["volume_mm3"], float(expected[0]["volume_mm3"]), 2)
            for name in ("heart", "spine"):
                self.assertEqual(report(os.path.join(py_out, name), py_out),
                                 report(os.path.join(cli_out, name), cli_out), name)
                self.assertEqual(sorted(os.listdir(os.path.join(py_out, name))),
                                 ["case.json", "report.json", "scene.glb"])
            with open(os.path.join(py_out, "spine", "report.json")) as f:
                self.assertEqual(json.load(f)["options"]["smooth"]["iterations"], 7)
            self.assertEqual(sorted(os.listdir(py_out)), ["heart", "spine", "summary.csv"])

    def test_finished_case_is_skipped_and_force_redoes_it(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        with TempDir() as out:
            first = segmesh.run_case(heart, out)
            self.assertEqual(first["status"], "ok", first["error"])
            self.assertEqual(first["case"], "heart_seg")
            glb = os.path.join(out, "heart_seg", "scene.glb")
            mtime = os.stat(glb).st_mtime_ns
            again = segmesh.run_case(heart, out)
            self.assertEqual(again["status"], "skipped")
            self.assertEqual(without(again, TIMES + ("status", "warnings")),
                             without(first, TIMES + ("status", "warnings")))
            self.assertEqual(os.stat(glb).st_mtime_ns, mtime)
            forced = segmesh.run_case(heart, out, force=True)
            self.assertEqual(forced["status"], "ok")
            self.assertNotEqual(os.stat(glb).st_mtime_ns, mtime)
            # Another input under the same name is not this case's: it is meshed again.
            other = segmesh.run_case(data("dcmqi", "spine_seg.nrrd"), out, "heart_seg")
            self.assertEqual(other["status"], "ok")
            self.assertNotEqual(other["triangles"], first["triangles"])
            self.assertEqual(hidden(out), [])

    def test_stale_temporaries_of_the_case_go_and_another_cases_stay(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        with TempDir() as out:
            # A killed run of this case, and a live temporary folder of a case named
            # "heart_seg.tmp-1", whose name begins like this case's temporaries.
            for stale in (".heart_seg.tmp-4242", ".heart_seg.old-4243"):
                os.makedirs(os.path.join(out, stale, "part"))
            live = ".heart_seg.tmp-1.tmp-4244"
            os.makedirs(os.path.join(out, live))
            row = segmesh.run_case(heart, out)
            self.assertEqual(row["status"], "ok", row["error"])
            self.assertEqual(hidden(out), [live])
            os.makedirs(os.path.join(out, ".heart_seg.tmp-77"))
            segmesh._segmesh.remove_case_temporaries(out, "heart_seg")
            self.assertEqual(hidden(out), [live])

    def test_bad_arguments_raise_before_anything_is_written(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        with TempDir() as tmp:
            out = os.path.join(tmp, "out")
            for kwargs, message in [({"connectivity": 7}, "--connectivity must be 6, 18 or 26"),
                                    ({"format": "fbx"}, "--format must be stl, ply, obj or glb"),
                                    ({"format": "stl", "quantize": True}, "--quantize"),
                                    ({"conectivity": 6}, "unknown option conectivity"),
                                    ({"name": "../up"}, "is not a folder name")]:
                with self.assertRaisesRegex(ValueError, message):
                    segmesh.run_case(heart, out, **kwargs)
            with self.assertRaisesRegex(ValueError, "--shard must be I/N"):
                segmesh.cohort([heart], out, shard="4/3")
            manifest = os.path.join(tmp, "m.csv")
            with open(manifest, "w") as f:
                f.write(f"path,iterations\n{heart},many\n")
            with self.assertRaisesRegex(ValueError, "m.csv:2: --iterations"):
                segmesh.cohort([manifest], out)
            self.assertFalse(os.path.exists(out))

    def test_progress_is_reported_and_the_gil_released(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        steps, counted, stop = [], [0], threading.Event()

        def count():  # pure Python: runs only while run_case does not hold the GIL
            while not stop.is_set():
                counted[0] += 1

        counter = threading.Thread(target=count)
        counter.start()
        try:
            with TempDir() as out:
                row = segmesh.run_case(heart, out, progress=lambda step, f: steps.append(step))
                before = counted[0]
                row2 = segmesh.run_case(heart, out, force=True)
                during = counted[0] - before
        finally:
            stop.set()
            counter.join()
        self.assertEqual(row["status"], "ok")
        self.assertEqual(row2["status"], "ok")
        self.assertIn("reading", steps)
        self.assertGreater(during, 10000)  # the counting thread ran during the second case


if __name__ == "__main__":
    unittest.main()
