#!/usr/bin/python3
"""tools/console against the emulated target (QEMU mps2-an386).

usage: console_qemu_test.py INTERACTIVE.elf EXITING.elf
INTERACTIVE.elf: the interactive image (pil_interactive: no script, runs until
stopped); EXITING.elf: an image that ends by itself (a PIL test image).
Checks that the console waits for the calibration before its first command
(so "arm" is answered ok, not err 8 state), that the target obeys the user's
commands only (the speed it reaches is the one commanded), that QEMU's own
exit is reported with exit status 3, that a target it cannot reach gives
exit status 2, and that long commands while the drive runs (listings) leave it
running.
"""
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
CONSOLE = os.path.join(HERE, "console")
ELF = None
ELF_EXITS = None


def console(*args, timeout=120):
    return subprocess.run([sys.executable, CONSOLE] + list(args), capture_output=True, text=True,
                          timeout=timeout)


class ConsoleQemuTest(unittest.TestCase):
    def test_drives_the_interactive_image(self):
        with tempfile.TemporaryDirectory() as tmp:
            csv = os.path.join(tmp, "run.csv")
            r = console("--qemu", ELF, "--timeout", "30", "--cmd", "ref speed 500", "--cmd", "arm",
                        "--cmd", "tel start speed torque every 10", "--duration", "3",
                        "--cmd", "tel stop", "--cmd", "status", "--cmd", "disarm",
                        "--record", csv)
            print(r.stdout[-1500:], r.stderr[-800:])
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("console: target ready (state ready)", r.stderr)
            self.assertIn("> arm\nok armed", r.stdout)
            self.assertIn("  state=running", r.stdout)
            self.assertRegex(r.stdout, r"  speed_ref_rpm=(499\.99|500)")
            self.assertIn("> disarm\nok disarmed", r.stdout)
            # Nothing but the user's commands: no script lines echoed.
            self.assertNotIn("> ref torque", r.stdout)
            with open(csv) as fh:
                rows = [ln.split(",") for ln in fh.read().splitlines()[1:]]
            self.assertGreater(len(rows), 50)
            with open(csv) as fh:
                header = fh.readline().strip().split(",")
            k = header.index("speed")
            speeds = [float(x[k]) for x in rows]
            tail = speeds[-20:]
            # The speed loop holds the commanded 500 r/min (the estimate's
            # quantisation and the loop's ripple: a few r/min).
            self.assertLess(max(abs(s - 500.0) for s in tail), 25.0, tail)

    def test_long_commands_while_running(self):
        # A command runs with the interrupts masked in the QEMU images: a long
        # one (a listing) delays the period's interrupt past its tick. The next
        # tick must not cut short that period's medium task (a deadline fault,
        # 29 of 30 listings faulted before the timer's realignment).
        cmds = ["ref speed 1000", "arm"]
        for _ in range(30):
            cmds += ["param list", "status"]
        args = ["--qemu", ELF, "--timeout", "30"]
        for c in cmds:
            args += ["--cmd", c]
        r = console(*args)
        states = [ln.strip() for ln in r.stdout.splitlines() if ln.strip().startswith("state=")]
        faults = [ln.strip() for ln in r.stdout.splitlines() if ln.strip().startswith("fault=")]
        self.assertEqual(r.returncode, 0, r.stderr[-800:])
        self.assertEqual(states, ["state=running"] * 30, faults)

    def test_settings_commands(self):
        # The settings record in the image's RAM model of the flash pages:
        # saved, listed, the compiled-in defaults back, erased.
        r = console("--qemu", ELF, "--timeout", "30", "--cmd", "ctrl select foc",
                    "--cmd", "config save", "--cmd", "config show", "--cmd", "config default",
                    "--cmd", "status", "--cmd", "config erase")
        print(r.stdout[-1500:], r.stderr[-800:])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("> config save\nok saved record 1", r.stdout)
        self.assertIn("  record=1\n", r.stdout)
        self.assertIn("  ctrl=foc\n", r.stdout)
        self.assertIn("ok compiled-in defaults applied (flash unchanged)", r.stdout)
        self.assertIn("  ctrl=fst\n", r.stdout)  # the image's compiled-in controller
        self.assertIn("ok erased: compiled-in defaults from the next start", r.stdout)

    def test_reports_the_target_exit(self):
        # The test image calibrates on a turning rotor (RK4 with the gates
        # off, millions of instructions a period): a patient response timeout.
        r = console("--qemu", ELF_EXITS, "--wait-ready", "0", "--timeout", "60", "--cmd", "status",
                    "--duration", "60")
        self.assertEqual(r.returncode, 3, r.stderr)
        self.assertRegex(r.stderr, r"console: the target exited with status \d+")

    def test_cannot_connect(self):
        r = console("--qemu", "/nope.elf", "--cmd", "status", timeout=30)
        self.assertEqual(r.returncode, 2)
        self.assertIn("no such readable file", r.stderr)
        r = console("--tcp", "127.0.0.1:1", "--cmd", "status", timeout=30)
        self.assertEqual(r.returncode, 2)
        self.assertIn("cannot connect", r.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: console_qemu_test.py INTERACTIVE.elf EXITING.elf")
    ELF, ELF_EXITS = sys.argv[1], sys.argv[2]
    del sys.argv[1:3]
    unittest.main(verbosity=2)
