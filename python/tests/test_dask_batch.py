"""python3 -m segmesh.batch on a dask.distributed LocalCluster (issue 38), on loopback: the same
summary.csv as `segmesh batch` (except seconds) and exit code 1 with a corrupt and a missing case,
a second run skipping every finished case; a worker killed in the middle of a case (the case is
retried, or recorded as failed once retries are used up; never lost, never half written, no
temporary folder left); shards 1/3..3/3, run on an existing cluster (--scheduler), covering every case once."""

import csv
import os
import re
import signal
import subprocess
import sys
import time
import unittest

import segmesh
from support import TempDir, data, run_cli

try:
    import distributed
except ImportError:  # Debian: python3-distributed, python3-dask (scripts/install-deps.sh)
    distributed = None


def read_summary(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def without_seconds(rows):
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


def hidden(out_dir):
    return sorted(e for e in os.listdir(out_dir) if e.startswith("."))


def dask_batch(*args, **popen):
    """`python3 -m segmesh.batch ARGS` in its own session, so that a failed test can end it and
    the cluster it started."""
    return subprocess.Popen([sys.executable, "-m", "segmesh.batch", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True, **popen)


def finish(test, proc, timeout=120):
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        test.fail("segmesh.batch did not finish")
    return proc.returncode, err


@unittest.skipIf(distributed is None, "dask.distributed is not installed (Debian: python3-distributed)")
class DaskBatch(unittest.TestCase):
    def check_case_folders(self, out, rows):
        """Every ok case's folder is complete, no failed case has one, nothing hidden is left."""
        for r in rows:
            folder = os.path.join(out, r["case"])
            if r["status"] in ("ok", "skipped"):
                self.assertEqual(sorted(os.listdir(folder)), ["case.json", "report.json", "scene.glb"])
            else:
                self.assertFalse(os.path.exists(folder), r["case"])
        self.assertEqual(hidden(out), [])

    def test_same_summary_as_the_cli_and_a_second_run_skips(self):
        inputs = [data("dcmqi", "heart_seg.nrrd"), data("dcmqi", "spine_seg.nrrd")]
        with TempDir() as tmp:
            corrupt = os.path.join(tmp, "corrupt.nrrd")
            with open(corrupt, "w") as f:
                f.write("not a volume at all, only text pretending to be NRRD\n")
            inputs += [corrupt, data("dcmqi", "liver_spine_seg.nrrd"),
                       os.path.join(tmp, "missing.nii.gz"),
                       data("totalsegmentator", "example_seg.nii.gz")]
            cli_out, dask_out = os.path.join(tmp, "cli"), os.path.join(tmp, "dask")
            self.assertEqual(run_cli("batch", *inputs, "-o", cli_out, "--quiet").returncode, 1)
            code, err = finish(self, dask_batch(*inputs, "-o", dask_out, "--workers", "2"))
            self.assertEqual(code, 1, err)
            self.assertIn("6 cases (2 failed) of 6; summary", err)
            self.assertRegex(err, r"\[\d/6\] example_seg ok")
            expected = read_summary(os.path.join(cli_out, "summary.csv"))
            rows = read_summary(os.path.join(dask_out, "summary.csv"))
            self.assertEqual(without_seconds(rows), without_seconds(expected))
            self.assertEqual([r["status"] for r in rows], ["ok", "ok", "failed", "ok", "failed", "ok"])
            self.check_case_folders(dask_out, rows)

            code, err = finish(self, dask_batch(*inputs, "-o", dask_out, "--workers", "2", "--quiet"))
            self.assertEqual(code, 1, err)
            again = read_summary(os.path.join(dask_out, "summary.csv"))
            self.assertEqual([r["status"] for r in again],
                             ["skipped", "skipped", "failed", "skipped", "failed", "skipped"])
            self.assertEqual([r["triangles"] for r in again], [r["triangles"] for r in rows])

    def kill_mid_case(self, retries):
        """A cohort of two small cases and one slow one (a phantom smoothed 300 times, a manifest
        cell); the worker meshing the slow one is killed as soon as its temporary folder
        .slow.tmp-<pid> appears (the pid is the worker's). Returns the summary, the output folder's
        listing and the pid killed."""
        with TempDir() as tmp:
            slow = os.path.join(tmp, "slow.nrrd")
            run_cli("phantom", "-o", slow, "--size", "256,256,100", "--spacing", "0.4,0.4,4",
                    "--quiet")
            manifest = os.path.join(tmp, "cohort.csv")
            with open(manifest, "w") as f:
                f.write(f"path,iterations\n{data('dcmqi', 'heart_seg.nrrd')},\n{slow},300\n"
                        f"{data('dcmqi', 'spine_seg.nrrd')},\n")
            out = os.path.join(tmp, "out")
            proc = dask_batch(manifest, "-o", out, "--workers", "2", "--retries", str(retries))
            killed, deadline = None, time.monotonic() + 60
            while killed is None and time.monotonic() < deadline and proc.poll() is None:
                for entry in os.listdir(out) if os.path.isdir(out) else []:
                    m = re.fullmatch(r"\.slow\.tmp-(\d+)", entry)
                    if m:
                        killed = int(m.group(1))
                        os.kill(killed, signal.SIGKILL)
                        break
                time.sleep(0.005)
            code, err = finish(self, proc)
            self.assertIsNotNone(killed, "the slow case's temporary folder never appeared: " + err)
            rows = read_summary(os.path.join(out, "summary.csv"))
            self.assertEqual([r["case"] for r in rows], ["heart_seg", "slow", "spine_seg"])
            self.check_case_folders(out, rows)
            return code, err, rows

    def test_a_killed_worker_s_case_is_retried(self):
        code, err, rows = self.kill_mid_case(retries=2)
        self.assertEqual(code, 0, err)
        self.assertEqual([r["status"] for r in rows], ["ok", "ok", "ok"], err)

    def test_a_killed_worker_s_case_without_retries_is_recorded_failed(self):
        code, err, rows = self.kill_mid_case(retries=0)
        self.assertEqual(code, 1, err)
        self.assertEqual([r["status"] for r in rows], ["ok", "failed", "ok"], err)
        self.assertRegex(rows[1]["error"], r"slow\.nrrd: the worker meshing it died")

    def test_shards_cover_every_case_exactly_once(self):
        heart, spine = data("dcmqi", "heart_seg.nrrd"), data("dcmqi", "spine_seg.nrrd")
        with TempDir() as tmp:
            for sub, src in (("a", heart), ("b", spine)):
                os.makedirs(os.path.join(tmp, sub))
                os.symlink(src, os.path.join(tmp, sub, "seg.nrrd"))
            gone = [os.path.join(tmp, f"gone{i}.nrrd") for i in range(1, 5)]
            inputs = [os.path.join(tmp, "a"), os.path.join(tmp, "b"), *gone[:3], spine, gone[3]]
            out = os.path.join(tmp, "out")
            seen = []
            # An existing cluster (--scheduler), here one in this process on loopback TCP: worker
            # threads, quick to start; the cases take the same path as on worker processes.
            cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                               protocol="tcp", host="127.0.0.1",
                                               dashboard_address=None)
            with cluster:
                for shard in (1, 2, 3):
                    code, err = finish(self, dask_batch(*inputs, "-o", out, "--quiet", "--shard",
                                                        f"{shard}/3", "--scheduler",
                                                        cluster.scheduler_address))
                    self.assertEqual(code, 1, err)  # every shard holds a missing case
                    seen += read_summary(os.path.join(out, f"summary-{shard}-of-3.csv"))
            self.assertFalse(os.path.exists(os.path.join(out, "summary.csv")))
            expected = [("a_seg", os.path.join(tmp, "a", "seg.nrrd")),
                        ("b_seg", os.path.join(tmp, "b", "seg.nrrd"))]
            expected += [(f"gone{i}", gone[i - 1]) for i in range(1, 5)] + [("spine_seg", spine)]
            self.assertEqual(sorted((r["case"], r["input"]) for r in seen), sorted(expected))
            for name in ("a_seg", "b_seg", "spine_seg"):
                self.assertTrue(os.path.exists(os.path.join(out, name, "case.json")), name)

    def test_local_workers_allocate_with_jemalloc(self):
        """The local cluster's workers run on the segmesh program's allocator: jemalloc, preloaded
        (segmesh.batch._worker_allocator), where it is installed."""
        import ctypes.util
        if ctypes.util.find_library("jemalloc") is None or "LD_PRELOAD" in os.environ:
            self.skipTest("no jemalloc installed, or LD_PRELOAD set by the environment")
        from distributed import Client
        from segmesh.batch import _local_cluster
        cluster = _local_cluster(1, 0)
        try:
            with Client(cluster) as client:
                maps = client.run(lambda: open("/proc/self/maps").read())
                conf = client.run(lambda: os.environ.get("MALLOC_CONF"))
        finally:
            cluster.close()
        self.assertEqual(len(maps), 1)
        for worker, text in maps.items():
            self.assertIn("libjemalloc", text, worker)
        expected = os.environ.get("MALLOC_CONF", "thp:always,metadata_thp:auto")
        self.assertEqual(set(conf.values()), {expected})

    def test_bad_arguments_exit_2_and_write_nothing(self):
        heart = data("dcmqi", "heart_seg.nrrd")
        with TempDir() as tmp:
            out = os.path.join(tmp, "out")
            for args, message in [(["--shard", "4/3"], "--shard must be I/N"),
                                  (["--connectivity", "7"], "--connectivity must be 6, 18 or 26"),
                                  (["--workers", "0"], "--workers must be at least 1")]:
                code, err = finish(self, dask_batch(heart, "-o", out, *args))
                self.assertEqual(code, 2, err)
                self.assertIn(message, err)
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
