#!/usr/bin/python3
"""tools/study's input handling, its local default and its store (ctest study_input).

usage: study_input_test.py SIM

  * bad input refused with exit status 2, the file, line, key and value named:
    an unknown key, an impossible distribution (outside the parameter's domain,
    empty, no spread), a malformed file, a missing machine file; an unreachable
    scheduler named by its address, within the connection time-out;
  * a run that faults is a result with its reason (exit 0, the table's status and
    reason, the report's list), and a refused run likewise;
  * the local cluster's table (two workers) equals the serial run's byte for byte;
  * a client killed mid-study loses nothing stored: the next invocation computes
    exactly the runs that are missing.
"""
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
STUDY = os.path.join(ROOT, "tools", "study")
sys.path.insert(0, os.path.join(ROOT, "tools"))
import study_spec  # noqa: E402
from study_testutil import STALL_S, free_port, watch  # noqa: E402
PY = "/usr/bin/python3"
SIM = None

GOOD = """[study]
name = "t"
seed = 3
samples = 1
controllers = ["foc"]
duration_s = 0.04
window_s = [0.02, 0.04]

[machines]
spmsm = "thesis_spmsm.ini"

[[points]]
mode = "torque"
speed_pu = 0.25
torque_pu = 0.5

[spread]
rs = { dist = "uniform", lo = -0.1, hi = 0.1 }
"""

# mbst cannot turn the flux fast enough at 2250 r/min on 220 V (its voltage limit,
# docs/algorithms.md "MBST's speed limit"): it trips on over-current. --fs 500 is
# below the simulator's range: refused. Both are results, not crashes.
FAULTY = """[study]
name = "f"
seed = 1
samples = 2
controllers = ["mbst", "foc"]
duration_s = 0.05
window_s = [0.025, 0.05]

[machines]
spmsm = "thesis_spmsm.ini"

[[points]]
mode = "torque"
speed_rpm = 2250
torque_nm = 1.8

[spread]
psi_pm = { dist = "uniform", lo = -0.05, hi = 0.05 }
"""


def study(path, *args):
    """tools/study on path with args (stdout, stderr, exit status), given up only when
    it is stuck: no new result in its store and no output for STALL_S."""
    args = list(args)
    store = os.path.join(args[args.index("--out") + 1], "runs.sqlite") if "--out" in args else None
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        p = subprocess.Popen([PY, STUDY, path, "--sim", SIM, "--progress", "text"] + args,
                             stdout=out, stderr=err, text=True, start_new_session=True)
        rc, _took = watch(p, store, [out, err])
        if rc is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            raise AssertionError(f"tools/study {' '.join(args)}: stuck, no new result nor "
                                 f"output for {STALL_S} s")
        out.seek(0)
        err.seek(0)
        return subprocess.CompletedProcess(p.args, p.returncode, out.read(), err.read())


class Base(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="study-input-")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, text, name="s.toml"):
        p = os.path.join(self.tmp, name)
        with open(p, "w") as f:
            f.write(text)
        return p


class BadInput(Base):
    def refused(self, text, *pattern, cli=False):
        """The file refused with the patterns in its message: through tools/study (exit
        status 2, no traceback) with cli, else by the checker tools/study calls."""
        p = self.write(text)
        if cli:
            r = study(p, "--dry-run")
            self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
            self.assertNotIn("Traceback", r.stderr)
            msg = r.stderr
        else:
            with self.assertRaises(study_spec.SpecError) as cm:
                study_spec.Spec(p)
            msg = f"study: error: {cm.exception}"
        for pat in pattern:
            self.assertRegex(msg, pat.replace("FILE", p))
        return msg

    def test_good_file_counts_its_runs(self):
        r = study(self.write(GOOD), "--dry-run")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("study t: 2 runs", r.stdout)

    def test_unknown_key(self):
        self.refused(GOOD.replace("seed = 3", "sede = 3"),
                     r"^study: error: FILE:3: study\.sede: unknown key \(allowed: ", cli=True)
        self.refused(GOOD.replace("torque_pu = 0.5", "torque_pu = 0.5\nload_pu = 0.5"),
                     r"FILE:16: points\.0\.load_pu: does not apply to a torque-mode point")
        self.refused(GOOD.replace("rs = {", "rz = {"),
                     r"FILE:18: spread\.rz: unknown parameter \(known: rs, ")
        self.refused(GOOD.replace('dist = "uniform"', 'dist = "uniform", sd = 0.1'),
                     r"FILE:18: spread\.rs\.sd: not a parameter of a uniform distribution")

    def test_impossible_distribution(self):
        self.refused(GOOD.replace("lo = -0.1", "lo = -1.5"),
                     r"FILE:18: spread\.rs\.lo: -1\.5 is outside the parameter's domain: a "
                     r"deviation in \(-1, 10\] \(the quantity would not be positive\)", cli=True)
        self.refused(GOOD.replace("lo = -0.1, hi = 0.1", "lo = 0.1, hi = -0.1"),
                     r"FILE:18: spread\.rs\.hi: lo 0\.1 >= hi -0\.1: an empty distribution")
        self.refused(GOOD.replace('rs = { dist = "uniform", lo = -0.1, hi = 0.1 }',
                                  'dead_time_ns = { dist = "normal", sd = 0, lo = 0, hi = 900 }'),
                     r"FILE:18: spread\.dead_time_ns\.sd: 0: a standard deviation > 0")
        self.refused(GOOD.replace('rs = { dist = "uniform", lo = -0.1, hi = 0.1 }',
                                  'current_gain = { dist = "normal", sd = 0.01 }'),
                     r"FILE:18: spread\.current_gain: a normal distribution needs lo")
        self.refused(GOOD.replace('rs = { dist = "uniform", lo = -0.1, hi = 0.1 }',
                                  'current_gain = { dist = "uniform", lo = -0.3, hi = 0.3 }'),
                     r"spread\.current_gain\.lo: -0\.3 is outside the parameter's domain: a "
                     r"value in \[-0\.25, 0\.25\]")
        self.refused(GOOD.replace('"uniform"', '"lognormal"'),
                     r"FILE:18: spread\.rs\.dist: 'lognormal': unknown distribution")

    def test_other_values(self):
        self.refused(GOOD.replace("samples = 1", "samples = -1"),
                     r"FILE:4: study\.samples: -1 is outside the allowed range")
        self.refused(GOOD.replace('"thesis_spmsm.ini"', '"nosuch.ini"'),
                     r"FILE:10: machines\.spmsm: machine file 'nosuch\.ini' not found")
        self.refused(GOOD.replace("window_s = [0.02, 0.04]", "window_s = [0.02, 0.4]"),
                     r"FILE:7: study\.window_s: \[0\.02, 0\.4\]: need 0 <= start < end <= "
                     r"duration")
        self.refused(GOOD.replace("speed_pu = 0.25\n", ""),
                     r"FILE:12: points\.0: give exactly one of speed_pu and speed_rpm")
        self.refused(GOOD.replace("[machines]", "[machines\n"),
                     r"FILE: not a valid TOML file: .*at line 9, column 10")

    def test_unreachable_scheduler(self):
        port = free_port()  # nothing listens there
        p = self.write(GOOD)
        t0 = time.monotonic()
        r = study(p, "--scheduler", f"tcp://127.0.0.1:{port}", "--connect-timeout", "2",
                  "--out", self.tmp)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"--scheduler tcp://127.0.0.1:{port}: no dask scheduler reachable within "
                      "2 s", r.stderr)
        self.assertLess(time.monotonic() - t0, 60)
        r = study(p, "--scheduler", "127.0.0.1:8786", "--out", self.tmp)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--scheduler '127.0.0.1:8786': expected tcp://HOST:PORT", r.stderr)


class Results(Base):
    def test_fault_is_a_result_and_workers_do_not_change_the_table(self):
        p = self.write(FAULTY)
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        r = study(p, "--out", a, "--jobs", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("local dask cluster, 2 workers", r.stderr)
        # the summary groups the three faults (each at its own time) as one kind
        self.assertRegex(r.stderr, r"\n  3 fault: the drive faulted: overcurrent at t = [0-9.]+ s "
                                   r"\(and 2 alike with other numbers\) \[mbst ")
        with open(os.path.join(a, "f.csv")) as f:
            rows = f.read().splitlines()
        mbst = [ln for ln in rows if ",mbst," in ln]
        self.assertEqual(len(mbst), 3)
        for ln in mbst:
            self.assertRegex(ln, r",fault,the drive faulted: overcurrent at t = 0\.0\d+ s,,")
        self.assertTrue(all(",ok,," in ln for ln in rows if ",foc," in ln), rows)
        with open(os.path.join(a, "f.md")) as f:
            md = f.read()
        self.assertIn("| mbst | thesis_spmsm | 2250 r/min, 1.8 N·m | 0 | fault | the drive "
                      "faulted: overcurrent", md)
        self.assertIn("**3 of 3 runs without indices**", md)
        r = study(p, "--out", b, "--serial")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(a, "f.csv"), "rb") as fa, open(os.path.join(b, "f.csv"), "rb") as fb:
            self.assertEqual(fa.read(), fb.read())

    def test_killed_client_loses_nothing(self):
        p = self.write(GOOD.replace("samples = 1", "samples = 9"))  # 10 runs
        out = os.path.join(self.tmp, "k")
        store = os.path.join(out, "runs.sqlite")
        proc = subprocess.Popen([PY, STUDY, p, "--sim", SIM, "--out", out, "--jobs", "1",
                                 "--progress", "none"], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, start_new_session=True)
        killed = []

        def kill_at_3(n):
            if n >= 3 and not killed:
                os.killpg(proc.pid, signal.SIGKILL)
                killed.append(n)

        try:
            watch(proc, store, on_progress=kill_at_3)  # given up if no result for STALL_S
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        self.assertEqual(proc.returncode, -signal.SIGKILL, "the client was killed mid-study")
        db = sqlite3.connect(store)
        before = db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
        db.close()
        self.assertTrue(3 <= before < 10, before)
        r = study(p, "--out", out, "--jobs", "1")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"10 runs: {10 - before} computed (local dask cluster, 1 worker), "
                      f"{before} from the store", r.stderr)


if __name__ == "__main__":
    SIM = os.path.abspath(sys.argv.pop(1))
    unittest.main(verbosity=2)
