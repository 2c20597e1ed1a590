"""Sweeps from Python and on a real Dask cluster (a `dask scheduler` and `dask worker`
processes on 127.0.0.1, started and torn down by each test, and set to exit by themselves
if left behind): the same table as the local sweep, a killed worker loses nothing, an
interrupted sweep resumes running only what is missing, an unreachable scheduler is
refused with exit status 2 and nothing written."""
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import fretbuzz

CLI = os.environ.get("FRETBUZZ_CLI")
MODULE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(fretbuzz.__file__)))

# The C++ sweep tests' case (tests/SweepTestCases.hpp), an ideal string plucked against
# a point obstacle: cheap, with contact in every run.
def note_case(duration):
    header = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "SweepTestCases.hpp")
    with open(header) as f:
        text = f.read()
    text = text[text.index('R"(') + 3:text.index(')";')]
    assert "duration = 0.01\n" in text
    return text.replace("duration = 0.01\n", f"duration = {duration}\n")


SPEC = """[sweep]
case = "note.toml"
[[parameter]]
key = "contact.K"
values = [1e8, 1e9, 1e10, 1e11]
[[parameter]]
key = "excitation.amplitude"
values = {amplitudes}
"""


def write_study(folder, duration, amplitudes):
    with open(os.path.join(folder, "note.toml"), "w") as f:
        f.write(note_case(duration))
    path = os.path.join(folder, "spec.toml")
    with open(path, "w") as f:
        f.write(SPEC.format(amplitudes=amplitudes))
    return path


def read(path):
    with open(path, "rb") as f:
        return f.read()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def row_files(out):
    runs = os.path.join(out, "runs")
    return sorted(n for n in os.listdir(runs) if n.endswith(".json")) if os.path.isdir(runs) else []


def wait_for(condition, timeout, what):
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


class DaskProcesses:
    """A scheduler and `workers` single-threaded workers (no nanny: a killed worker stays
    dead) on 127.0.0.1; they exit by themselves after 120 s idle / without a scheduler."""

    def __init__(self, folder, workers=2):
        self.folder = folder
        env = dict(os.environ)
        env["PYTHONPATH"] = MODULE_DIR + os.pathsep + env.get("PYTHONPATH", "")
        env["DASK_DISTRIBUTED__SCHEDULER__IDLE_TIMEOUT"] = "120s"
        self.env = env
        self.log = open(os.path.join(folder, "dask.log"), "w")
        file = os.path.join(folder, "scheduler.json")
        self.processes = []
        self.scheduler = self._start(["dask", "scheduler", "--host", "127.0.0.1", "--port", str(free_port()),
                                      "--no-dashboard", "--scheduler-file", file])
        self.address = None
        try:
            wait_for(lambda: os.path.exists(file) and os.path.getsize(file) > 0, 60, "the scheduler")
            import json
            with open(file) as f:
                self.address = json.load(f)["address"]
            self.workers = [self._start(["dask", "worker", self.address, "--host", "127.0.0.1", "--nthreads", "1",
                                         "--no-nanny", "--no-dashboard", "--death-timeout", "30",
                                         "--local-directory", os.path.join(folder, f"worker{k}")])
                            for k in range(workers)]
            from distributed import Client
            with Client(self.address, timeout=30, set_as_default=False) as client:
                client.wait_for_workers(workers, timeout=60)
        except BaseException:
            self.close()
            raise

    def _start(self, command):
        p = subprocess.Popen(command, env=self.env, stdout=self.log, stderr=subprocess.STDOUT,
                             stdin=subprocess.DEVNULL, start_new_session=True)
        self.processes.append(p)
        return p

    def close(self):
        for p in reversed(self.processes):
            if p.poll() is None:
                p.terminate()
        for p in self.processes:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.log.close()


@unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
class SweepTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="fretbuzz-sweep-test-")
        self.addCleanup(shutil.rmtree, self.folder, ignore_errors=True)

    def cli(self, *args, timeout=300):
        return subprocess.run([CLI, "sweep", *args], capture_output=True, text=True, timeout=timeout)

    def local_table(self, spec):
        out = os.path.join(self.folder, "local")
        if not os.path.exists(out):
            r = self.cli(spec, "--out", out, "--jobs", "2", "--quiet")
            self.assertEqual(r.returncode, 0, r.stderr)
        return read(os.path.join(out, "results.csv"))

    def cluster(self, workers=2):
        c = DaskProcesses(self.folder, workers)
        self.addCleanup(c.close)
        return c

    def test_python_sweep_returns_the_table_with_progress(self):
        spec = write_study(self.folder, 0.01, "[1e-3, 2e-3]")
        reports = []
        table = fretbuzz.sweep(spec, jobs=2, progress=reports.append)
        self.assertEqual(len(table), 8)
        self.assertEqual(list(table["status"]), ["ok"] * 8)
        self.assertEqual(list(table.columns[:3]), ["run", "contact.K", "excitation.amplitude"])
        self.assertEqual([p.done for p in reports], list(range(1, 9)))
        self.assertTrue(all(p.total == 8 and p.failed == 0 for p in reports))
        self.assertEqual(reports[-1].remaining_s, 0.0)
        # The same numbers as the command line's table, read by pandas.
        import pandas
        self.local_table(spec)
        cli_table = pandas.read_csv(os.path.join(self.folder, "local", "results.csv"), float_precision="round_trip")
        pandas.testing.assert_frame_equal(table.drop(columns=["error", "features"]),
                                          cli_table.drop(columns=["error", "features"]), check_exact=True)
        # The HDF5 table, read into pandas, is the same frame as the CSV one, bit for bit.
        out = os.path.join(self.folder, "local")
        pandas.testing.assert_frame_equal(fretbuzz.read_table(out, hdf5=True), fretbuzz.read_table(out),
                                          check_exact=True)
        # A contact stiffer or a pluck larger: harder contact.
        self.assertTrue((table["peak_contact_force_N"] > 0).all())
        big = table[table["excitation.amplitude"] == 2e-3]["peak_contact_force_N"].to_numpy()
        small = table[table["excitation.amplitude"] == 1e-3]["peak_contact_force_N"].to_numpy()
        self.assertTrue((big > small).all())

    def test_a_grid_past_the_run_limit_is_refused_and_checking_reports_progress(self):
        spec = write_study(self.folder, 0.01, "[1e-3]")
        with open(spec, "a") as f:
            f.write('[[parameter]]\nkey = "observe.x"\nfrom = 0.1\nto = 0.6\ncount = 100000\n')
        with self.assertRaisesRegex(fretbuzz.InputError, r"4 \(contact\.K\) x 1 \(excitation\.amplitude\) x 100000 "
                                                         r"\(observe\.x\) runs, more than the limit of 100000"):
            fretbuzz.sweep(spec)
        small = write_study(self.folder, 0.01, "[1e-3, 2e-3]")
        s = fretbuzz.SweepSpec.load(small, max_runs=8)
        self.assertEqual(s.max_runs, 8)
        with self.assertRaisesRegex(fretbuzz.InputError, "more than the limit of 7"):
            fretbuzz.SweepSpec.load(small, max_runs=7)
        seen = []
        s.check(lambda checked, total: seen.append((checked, total)))
        self.assertEqual(seen[-1], (8, 8))

    def test_bad_python_arguments_name_themselves(self):
        spec = write_study(self.folder, 0.01, "[1e-3]")
        with self.assertRaisesRegex(fretbuzz.InputError, "jobs"):
            fretbuzz.sweep(spec, jobs=0)
        with self.assertRaisesRegex(TypeError, "spec"):
            fretbuzz.sweep(3)
        with self.assertRaisesRegex(TypeError, "progress"):
            fretbuzz.sweep(spec, progress="yes")

    def test_dask_table_equals_the_local_table(self):
        spec = write_study(self.folder, 0.01, "[1e-3, 2e-3]")
        local = self.local_table(spec)
        c = self.cluster()
        out = os.path.join(self.folder, "dask")
        r = self.cli(spec, "--out", out, "--scheduler", c.address)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("8/8 runs", r.stderr)  # the progress lines
        self.assertEqual(read(os.path.join(out, "results.csv")), local)
        # From Python: the same table as a DataFrame.
        table = fretbuzz.sweep(spec, os.path.join(self.folder, "py-dask"), scheduler=c.address)
        self.assertEqual(read(os.path.join(self.folder, "py-dask", "results.csv")), local)
        self.assertEqual(len(table), 8)

    def test_a_killed_worker_loses_nothing(self):
        spec = write_study(self.folder, 0.1, "[1e-3, 1.5e-3, 2e-3]")
        local = self.local_table(spec)
        c = self.cluster()
        out = os.path.join(self.folder, "dask")
        driver = subprocess.Popen([CLI, "sweep", spec, "--out", out, "--scheduler", c.address, "--quiet"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            wait_for(lambda: len(row_files(out)) >= 1 or driver.poll() is not None, 120, "a first row")
            self.assertLess(len(row_files(out)), 12, "the sweep finished before a worker could be killed")
            c.workers[0].kill()  # mid-sweep: its task under way is lost with it
            _, err = driver.communicate(timeout=300)
        finally:
            if driver.poll() is None:
                driver.kill()
        self.assertEqual(driver.returncode, 0, err)
        self.assertEqual(len(row_files(out)), 12)
        self.assertEqual(read(os.path.join(out, "results.csv")), local)

    def test_an_interrupted_dask_sweep_resumes_only_what_is_missing(self):
        spec = write_study(self.folder, 0.1, "[1e-3, 1.5e-3, 2e-3]")
        local = self.local_table(spec)
        c = self.cluster()
        out = os.path.join(self.folder, "dask")
        driver = subprocess.Popen([CLI, "sweep", spec, "--out", out, "--scheduler", c.address, "--quiet"],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
        try:
            wait_for(lambda: len(row_files(out)) >= 2 or driver.poll() is not None, 120, "two rows")
            os.killpg(driver.pid, signal.SIGINT)  # Ctrl-C
            _, err = driver.communicate(timeout=60)
        finally:
            if driver.poll() is None:
                driver.kill()
        # Exit 130, and the message says how to finish (it used to die with no message).
        self.assertEqual(driver.returncode, 130, err)
        self.assertIn(f"--out {out} --scheduler {c.address} --resume", err)
        kept = row_files(out)
        self.assertGreaterEqual(len(kept), 2)
        self.assertLess(len(kept), 12, "the sweep finished before it could be interrupted")
        self.assertFalse(os.path.exists(os.path.join(out, "results.csv")))  # no half table
        before = {n: os.stat(os.path.join(out, "runs", n)).st_mtime_ns for n in kept}
        again = self.cli(spec, "--out", out, "--scheduler", c.address)
        self.assertEqual(again.returncode, 2, again.stderr)  # a second start needs --resume
        self.assertIn("--resume", again.stderr)
        r = self.cli(spec, "--out", out, "--scheduler", c.address, "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"({12 - len(kept)} computed, {len(kept)} from before", r.stderr)
        # The rows from before were not computed again, and the table is the local one.
        self.assertEqual(before, {n: os.stat(os.path.join(out, "runs", n)).st_mtime_ns for n in kept})
        self.assertEqual(read(os.path.join(out, "results.csv")), local)
        # A local resume of a finished sweep computes nothing and gives the same table.
        r = self.cli(spec, "--out", out, "--resume")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("(0 computed, 12 from before", r.stderr)
        self.assertEqual(read(os.path.join(out, "results.csv")), local)

    def test_an_unreachable_scheduler_is_refused_and_nothing_is_written(self):
        spec = write_study(self.folder, 0.01, "[1e-3]")
        out = os.path.join(self.folder, "nowhere")
        address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
        start = time.monotonic()
        r = self.cli(spec, "--out", out, "--scheduler", address, "--scheduler-timeout", "3", timeout=120)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--scheduler " + address, r.stderr)
        self.assertIn("within 3 s", r.stderr)
        self.assertLess(time.monotonic() - start, 60)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
