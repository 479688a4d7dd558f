#!/usr/bin/python3
"""Tests of tools/console_proto.py against the C encoder.

usage: console_test.py PATH/TO/proto_stream_gen
The generator writes a recorded stream made by firmware/telemetry.c (META,
samples, text responses, some frames damaged by a dropped or flipped byte)
and the list of what it contains; the Python decoder must return every
undamaged frame with the same values, drop every damaged one, keep the text
lines, and agree with the C signal table.
Also the console's helpers without a target: the build progress bar
(build_progress.py) and the web server's rules (console_web.py: what a
watching page may send, the phases of a flash run).
"""
import os
import struct
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import build_progress as bp  # noqa: E402
import console_proto as cp  # noqa: E402
import console_web as cw  # noqa: E402

GEN = None


class CodecTest(unittest.TestCase):
    def test_crc_check_value(self):
        self.assertEqual(cp.crc16(b"123456789"), 0x29B1)
        self.assertEqual(cp.crc16(b"123456789" + b"\x29\xB1"), 0)

    def test_cobs_reference(self):
        cases = [
            (b"", b"\x01"),
            (b"\x00", b"\x01\x01"),
            (b"\x00\x00", b"\x01\x01\x01"),
            (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
            (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
            (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255))),
            (bytes(range(1, 256)), b"\xff" + bytes(range(1, 255)) + b"\x02\xff"),
            (bytes(range(2, 256)) + b"\x00", b"\xff" + bytes(range(2, 256)) + b"\x01\x01"),
        ]
        for raw, enc in cases:
            self.assertEqual(cp.cobs_encode(raw), enc)
            self.assertEqual(cp.cobs_decode(enc), raw)
        self.assertIsNone(cp.cobs_decode(b"\x05\x11"))
        self.assertIsNone(cp.cobs_decode(b"\x03\x11\x00"))

    def test_resync_after_drop(self):
        frames = []
        for k in range(5):
            f = cp.Frame()
            f.type, f.seq, f.mask, f.tick = cp.TYPE_SAMPLE, k, 0x43, 10 * k
            f.values = [k, -k, 1 << 30]
            frames.append(cp.frame_encode(f))
        stream = b"".join(frames)
        start = len(frames[0]) + len(frames[1])
        for pos in range(start, start + len(frames[2])):
            dec = cp.StreamDecoder()
            ev = dec.feed(stream[:pos] + stream[pos + 1:])
            seqs = [v.seq for k, v in ev if k == "frame"]
            if pos in (start, start + len(frames[2]) - 1):
                # one of the frame's two delimiters: the other still separates it
                self.assertEqual(seqs, [0, 1, 2, 3, 4])
            else:
                self.assertEqual(seqs, [0, 1, 3, 4])


class RecordedStreamTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.bin = os.path.join(cls.tmp.name, "stream.bin")
        cls.exp = os.path.join(cls.tmp.name, "expect.txt")
        subprocess.run([GEN, cls.bin, cls.exp], check=True)
        with open(cls.bin, "rb") as fh:
            cls.data = fh.read()
        cls.samples, cls.meta, cls.text, cls.sigs = {}, None, [], []
        with open(cls.exp) as fh:
            for line in fh:
                kind, rest = line[0], line[2:].rstrip("\n")
                if kind == "T":
                    cls.text.append(rest)
                    continue
                p = rest.split()
                if kind == "N":
                    cls.sigs.append((p[1], "" if p[2] == "-" else p[2]))
                elif kind == "M":
                    cls.meta = (int(p[0]), int(p[1]), int(p[2]), int(p[3]),
                                [struct.unpack("<f", struct.pack("<I", int(x, 16)))[0]
                                 for x in p[5:]])
                elif kind == "S":
                    cls.samples[int(p[0])] = (int(p[1]), int(p[2]), int(p[3]),
                                              [int(x) for x in p[4:]])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_signal_table_matches_c(self):
        self.assertEqual(self.sigs, cp.SIGNALS)

    def test_decode(self):
        # feed in odd-sized pieces to exercise the streaming state
        dec = cp.StreamDecoder()
        ev = []
        for i in range(0, len(self.data), 37):
            ev += dec.feed(self.data[i:i + 37])
        got = {}
        metas = []
        for kind, v in ev:
            if kind == "frame" and v.type == cp.TYPE_SAMPLE:
                self.assertNotIn(v.seq, got)
                got[v.seq] = v
            elif kind == "frame":
                metas.append(v)
        damaged = {s for s, e in self.samples.items() if e[2]}
        clean = set(self.samples) - damaged
        self.assertGreater(len(damaged), 10)
        self.assertEqual(set(got), clean)  # every clean frame, no damaged one
        for seq, f in got.items():
            tick, mask, _, vals = self.samples[seq]
            self.assertEqual((f.tick, f.mask, f.values), (tick, mask, vals))
            # the Python encoder reproduces the C encoder's bytes
            self.assertIn(cp.frame_encode(f), self.data)
        self.assertEqual(len(metas), 1)
        m = metas[0]
        self.assertEqual((m.seq, m.mask, m.fs_hz, m.every), self.meta[:4])
        self.assertEqual(m.scales, self.meta[4])
        self.assertEqual(dec.bad, len(damaged))
        texts = [v for k, v in ev if k == "text"]
        self.assertEqual(texts, self.text)

    def test_console_offline_decode(self):
        csv = os.path.join(self.tmp.name, "out.csv")
        console = os.path.join(os.path.dirname(os.path.abspath(__file__)), "console")
        r = subprocess.run([sys.executable, console, "--decode", self.bin, "--record", csv],
                           capture_output=True, text=True, check=True)
        self.assertIn("bad %d" % sum(1 for e in self.samples.values() if e[2]), r.stderr)
        with open(csv) as fh:
            rows = fh.read().splitlines()
        self.assertEqual(rows[0], "seq,tick,time_s,i_a,i_b,torque,speed,vector,duty")
        clean = sorted(s for s, e in self.samples.items() if not e[2])
        self.assertEqual(len(rows) - 1, len(clean))
        # SI scaling: value * scale from META; time from fs
        first = rows[1].split(",")
        tick, _, _, vals = self.samples[clean[0]]
        self.assertEqual(int(first[1]), tick)
        for k, v in enumerate(vals):
            want = v * self.meta[4][k]
            self.assertLessEqual(abs(float(first[3 + k]) - want), 1e-8 * max(1.0, abs(want)))
        last = rows[-1].split(",")
        self.assertAlmostEqual(float(last[2]),
                               (self.samples[clean[-1]][0] - tick) / self.meta[2], places=9)


class BadInputTest(unittest.TestCase):
    def test_each_exits_2_naming_option_value_and_range(self):
        """Checked before anything connects or starts (a negative --timeout ran and ended
        with 'target went away', exit 3; --port 99999 with --web a traceback)."""
        console = os.path.join(os.path.dirname(os.path.abspath(__file__)), "console")
        cases = (
            (["--timeout", "-1"], "--timeout: '-1' is out of range: allowed a decimal number "
             "in (0, 3600] s"),
            (["--timeout", "nan"], "--timeout: 'nan' is out of range"),
            (["--duration", "-5"], "--duration: '-5' is out of range: allowed a decimal number "
             "in [0, "),
            (["--shift", "99"], "--shift: '99' is out of range: allowed a whole number in [0, 10]"),
            (["--baud", "fast"], "--baud: 'fast' is not a whole number: allowed a whole number "
             "in [50, "),
            (["--port", "99999", "--web"], "--port: '99999' is out of range: allowed a whole "
             "number in [0, 65535]"),
            (["--tcp", "localhost"], "--tcp: 'localhost': expected HOST:PORT with the port in "
             "[1, 65535]"))
        for args, want in cases:
            r = subprocess.run([sys.executable, console, "--exec", "true"] + args
                               if "--tcp" not in args else [sys.executable, console] + args,
                               capture_output=True, text=True, timeout=20)
            self.assertEqual(r.returncode, 2, args)
            self.assertIn(want, r.stderr, args)


class BuildProgressTest(unittest.TestCase):
    def test_counts_the_build_not_its_preamble_nor_an_inner_build(self):
        now = [0.0]
        out = open(os.devnull, "w")
        self.addCleanup(out.close)
        bar = bp.Bar("building x", out, tty=False, clock=lambda: now[0])
        self.assertFalse(bar.feed("[0/2] Re-checking globbed directories..."))
        now[0] = 4.0
        self.assertTrue(bar.feed("[2/5] Building C object a.obj"))
        # 4 s for 2 steps: 3 steps left take about 6 s
        self.assertIn("2/5", bar.text())
        self.assertIn("~0:06 left", bar.text())
        # a build inside a step prints its own status lines when the step ends
        self.assertFalse(bar.feed("[1/60] Building C object inner.o"))
        self.assertFalse(bar.feed("[60/60] Linking inner"))
        self.assertFalse(bar.feed("ninja: no work to do."))
        self.assertTrue(bar.feed("[5/5] Linking C executable x.elf"))
        self.assertEqual((bar.done, bar.total), (5, 5))
        self.assertNotIn("left", bar.text())

    def test_run_reports_status_and_tail(self):
        rc, tail = bp.run_with_bar(["sh", "-c", "printf '[1/2] a\\n[2/2] b\\nboom\\n'; exit 3"],
                                   "building t", out=open(os.devnull, "w"))
        self.assertEqual(rc, 3)
        self.assertEqual(tail[-1], "boom")


class WebRulesTest(unittest.TestCase):
    def test_a_watching_page_may_read_only(self):
        for line in ("status", "help", "fault", "param list", "param get h_T", "tel list",
                     "ctrl list", "ident status", "ident result", "ident ini", "bringup status",
                     "cogging status"):
            self.assertTrue(cw.reads_only(line), line)
        for line in ("", "arm", "fault clear", "param set h_T 0.1", "ctrl select bst", "stop",
                     "ident run", "bringup gates", "tel start speed", "config save", "disarm",
                     "ref speed 100", "statusx", "config show", "ident cogging", "cogging on"):
            self.assertFalse(cw.reads_only(line), line)

    def test_energising_commands_need_a_confirmation(self):
        for line in ("arm", "ident run", "ident resume", "ident step rs", "ident cogging",
                     "bringup gates", "bringup run"):
            self.assertTrue(cw.energises(line), line)
        for line in ("", "stop", "disarm", "ident status", "ident result", "bringup status",
                     "cogging on", "cogging status", "param set speed.kp 0.1"):
            self.assertFalse(cw.energises(line), line)

    def test_flash_phases_of_an_openocd_run(self):
        pct, phases = 0, []
        for line in ("tools/flash: programming pmsm-esc1.elf with openocd",
                     "Open On-Chip Debugger 0.12.0", "** Programming Started **",
                     "** Programming Finished **", "** Verify Started **", "** Verified OK **",
                     "** Resetting Target **", "tools/flash: pmsm-esc1.elf written and verified"):
            phase, pct2 = cw.flash_progress(line, pct)
            self.assertGreaterEqual(pct2, pct)
            pct = pct2
            if phase:
                phases.append(phase)
        self.assertEqual(pct, 100)
        self.assertEqual(phases[-1], "done")
        self.assertIn("verifying", phases)
        self.assertEqual(cw.flash_progress("  12/24 pages written", 20), ("writing", 40))


# A target that answers each line after 0.2 s (a flash erase: it reads
# nothing meanwhile) and says whether the next line had already arrived.
SLOW_TARGET = r"""
import os, select, sys
buf = b""
while True:
    while b"\n" not in buf:
        d = os.read(0, 256)
        if not d:
            sys.exit(0)
        buf += d
    line, buf = buf.split(b"\n", 1)
    select.select([], [], [], 0.2)
    early = bool(buf) or bool(select.select([0], [], [], 0)[0])
    os.write(1, b"err 99 overlapped\n" if early else b"ok 1\n  got=" + line + b"\n")
"""


class InteractiveTest(unittest.TestCase):
    def test_one_line_at_a_time(self):
        """Pasted lines go out one at a time, each after the reply before it."""
        console = os.path.join(os.path.dirname(os.path.abspath(__file__)), "console")
        r = subprocess.run([sys.executable, console, "--exec",
                            "%s -c '%s'" % (sys.executable, SLOW_TARGET.replace("'", "'\\''")),
                            "--wait-ready", "0", "--timeout", "3"],
                           input="config save\nconfig show\nstatus\n", capture_output=True,
                           text=True, timeout=30)
        self.assertNotIn("overlapped", r.stdout)
        self.assertEqual([ln.strip() for ln in r.stdout.splitlines() if "got=" in ln],
                         ["got=config save", "got=config show", "got=status"])


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: console_test.py PATH/TO/proto_stream_gen")
    GEN = sys.argv.pop(1)
    unittest.main(verbosity=1)
