#!/usr/bin/python3
"""./tools/demo's set-up and reuse decisions (tools/demo_main.py) and the quiet build
bar (tools/build_progress.py), without running the demo: a missing package is named
with the one command that installs it; the bench's fingerprint changes with any image
it counts and not otherwise; a bad option exits 2 naming it, its value and the range
before anything starts; a build with nothing to do prints nothing, one with
steps prints its bar and its total."""
import io
import os
import subprocess
import sys
import tempfile
import unittest
from contextlib import redirect_stdout

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import build_progress  # noqa: E402
import demo_main  # noqa: E402


class BadInput(unittest.TestCase):
    def test_each_exits_2_naming_option_value_and_range(self):
        """Before anything is set up or built: a time-out of 20 s would show it started."""
        demo = os.path.join(os.path.dirname(os.path.abspath(__file__)), "demo")
        for args, want in ((["--jobs", "0"], "--jobs: '0' is out of range: allowed a whole "
                            "number in [1, 1024] simulations at once"),
                           (["--jobs", "two"], "--jobs: 'two' is not a whole number: allowed a "
                            "whole number in [1, 1024]"),
                           (["--seed", "-1"], "--seed: '-1' is out of range: allowed a whole "
                            "number in [0, 9007199254740992]"),
                           (["--out", os.path.abspath(__file__)], "is a file: a folder is "
                            "expected"),
                           (["--nosuch"], "unrecognized arguments: --nosuch")):
            r = subprocess.run([demo] + args, capture_output=True, text=True, timeout=20)
            self.assertEqual(r.returncode, 2, args)
            self.assertIn(want, r.stderr, args)
            self.assertEqual(r.stdout, "", args)

    def test_the_demos_tools_too(self):
        """./tools/bench (the demo's cost columns) and ./tools/demo --qemu: --reps 0 and
        --jobs 0 started the builds; demo_qemu ran with any argument."""
        here = os.path.dirname(os.path.abspath(__file__))
        for cmd, want in (([os.path.join(here, "bench"), "--reps", "0"],
                           "--reps: '0' is out of range: allowed a whole number in [1, 10000]"),
                          ([os.path.join(here, "bench"), "--jobs", "x"],
                           "--jobs: 'x' is not a whole number: allowed a whole number in [1, "),
                          ([os.path.join(here, "demo"), "--qemu", "--fast"],
                           "demo_qemu: error: no options (got '--fast')")):
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=20)
            self.assertEqual(r.returncode, 2, cmd)
            self.assertIn(want, r.stderr, cmd)


class SetUp(unittest.TestCase):
    def setUp(self):
        self.have, self.euid = demo_main.have, os.geteuid

    def tearDown(self):
        demo_main.have, os.geteuid = self.have, self.euid

    def test_nothing_missing(self):
        demo_main.have = lambda kind, what: True
        self.assertEqual(demo_main.missing_packages(), [])
        self.assertTrue(demo_main.set_up())

    def test_missing_named_with_the_command(self):
        demo_main.have = lambda kind, what: what not in ("tqdm", "qemu-system-arm")
        os.geteuid = lambda: 1000  # not root: it cannot install
        self.assertEqual(demo_main.missing_packages(), ["python3-tqdm", "qemu-system-arm"])
        buf = io.StringIO()
        with redirect_stdout(buf):
            self.assertFalse(demo_main.set_up())
        out = buf.getvalue()
        self.assertIn("missing: python3-tqdm, qemu-system-arm", out)
        self.assertIn("    sudo ./tools/setup cmake ninja-build", out)
        self.assertEqual(sum(1 for ln in out.splitlines() if "sudo" in ln), 1)

    def test_every_needed_package_is_one_tools_setup_installs(self):
        with open(os.path.join(demo_main.ROOT, "tools", "setup")) as f:
            setup = f.read()
        for pkg, _ in demo_main.NEEDS:
            self.assertRegex(setup, r"[\s(]%s[\s)]" % pkg.replace("+", r"\+"), pkg)


class BenchReuse(unittest.TestCase):
    def test_fingerprint_follows_the_images(self):
        with tempfile.TemporaryDirectory() as root:
            old = demo_main.ROOT
            demo_main.ROOT = root
            try:
                self.assertIsNone(demo_main.bench_fingerprint())  # nothing built yet
                rec = os.path.join(root, "build", "host-release", "tests", "bench", "bench_fw")
                cm4 = os.path.join(root, "build", "cm4", "tests", "bench", "bench_fw")
                os.makedirs(rec)
                os.makedirs(cm4)
                for p, data in ((os.path.join(rec, "bench_rec"), b"rec"),
                                (os.path.join(cm4, "bench_cm4.elf"), b"isr"),
                                (os.path.join(cm4, "bench_size_bst.elf"), b"bst")):
                    with open(p, "wb") as f:
                        f.write(data)
                a = demo_main.bench_fingerprint()
                self.assertEqual(a, demo_main.bench_fingerprint())
                with open(os.path.join(cm4, "bench_cm4.map"), "w") as f:
                    f.write("not counted")
                self.assertEqual(a, demo_main.bench_fingerprint())
                with open(os.path.join(cm4, "bench_size_bst.elf"), "wb") as f:
                    f.write(b"bst, one instruction more")
                self.assertNotEqual(a, demo_main.bench_fingerprint())
            finally:
                demo_main.ROOT = old


class QuietBar(unittest.TestCase):
    def run_bar(self, script, quiet):
        buf = io.StringIO()
        rc, _ = build_progress.run_with_bar(["sh", "-c", script], "building x", out=buf,
                                            quiet=quiet)
        return rc, buf.getvalue()

    def test_nothing_built_says_nothing(self):
        rc, out = self.run_bar("printf '[0/1] Re-checking globbed directories...\\n'", True)
        self.assertEqual((rc, out), (0, ""))
        rc, out = self.run_bar("printf '[0/1] Re-checking globbed directories...\\n'", False)
        self.assertIn("building x: up to date", out)

    def test_silent_for_the_documentation(self):
        os.environ["PMSM_PROGRESS"] = "none"  # as tools/doc_examples.py runs the examples
        try:
            rc, out = self.run_bar("printf '[1/2] a\\n[2/2] b\\n'", True)
            self.assertEqual((rc, out), (0, ""))
            rc, out = self.run_bar("printf '[1/2] a\\n'; exit 1", True)
            self.assertEqual(rc, 1)
            self.assertIn("FAILED", out)  # a failure is always said
        finally:
            del os.environ["PMSM_PROGRESS"]

    def test_steps_show_count_and_total(self):
        rc, out = self.run_bar("printf '[1/2] a\\n[2/2] b\\n'", True)
        self.assertEqual(rc, 0)
        self.assertIn("2/2", out)
        self.assertIn("building x: 2 steps in", out)


class Needs(unittest.TestCase):
    def test_a_missing_program_is_named_with_the_command(self):
        """tools/sim and the console check before they configure a preset."""
        bp = os.path.join(os.path.dirname(os.path.abspath(__file__)), "build_progress.py")
        r = subprocess.run([sys.executable, bp, "--needs", "cm4", "no-such-program-here"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 1)
        self.assertIn("no-such-program-here not installed: run 'sudo ", r.stderr)
        self.assertIn("/tools/setup'", r.stderr)
        missing = build_progress.missing_tools
        build_progress.missing_tools = lambda preset: []
        try:
            ok, why = build_progress.ensure_built("/nonexistent", "cm4", "t", "/nonexistent/a",
                                                  runs_with=("no-such-program-here",))
        finally:
            build_progress.missing_tools = missing
        self.assertFalse(ok)
        self.assertIn("no-such-program-here not installed", why)


if __name__ == "__main__":
    unittest.main(verbosity=2)
