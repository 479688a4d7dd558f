#!/usr/bin/python3
"""The anti-cogging calibration's start on the emulated Cortex-M4.

usage: cogging_qemu_test.py CONSOLE INTERACTIVE.elf
`ident cogging` on the interactive image (QEMU mps2-an386, the thesis SPMSM
in the loop), no other command: the step must be running a few emulated
tenths of a second later (the first hold and the start of the forward sweep,
its periods each within the interrupt's deadline), not failed with fault 7
deadline. Its beginning runs in the period interrupt: clearing the per-bin
sums there at once (12 KiB) cost more than the whole period's budget.
The complete step (two sweeps of 20 s of plant time, ~15 min of wall time in
QEMU) is tests/cogging's host test; this one checks its periods fit on the
target.
"""
import subprocess
import sys
import unittest

CONSOLE = None
ELF = None


class CoggingQemuTest(unittest.TestCase):
    def test_ident_cogging_starts_without_a_fault(self):
        r = subprocess.run([sys.executable, CONSOLE, "--qemu", ELF, "--timeout", "30",
                            "--cmd", "ident cogging", "--duration", "6",
                            "--cmd", "ident status", "--cmd", "status"],
                           capture_output=True, text=True, timeout=120)
        print(r.stdout[-1500:], r.stderr[-800:])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("> ident cogging\nok ident cogging", r.stdout)
        self.assertNotIn("fail step=cogging", r.stdout)
        self.assertRegex(r.stdout, r"> ident status\nok running step=cogging progress=")
        self.assertIn("  fault=0 none", r.stdout)


if __name__ == "__main__":
    CONSOLE, ELF = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1], verbosity=2)
