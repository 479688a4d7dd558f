#!/usr/bin/python3
"""Tests of tools/console_proto.py against the C encoder.

usage: console_test.py PATH/TO/proto_stream_gen
The generator writes a recorded stream made by firmware/telemetry.c (META,
samples, text responses, some frames damaged by a dropped or flipped byte)
and the list of what it contains; the Python decoder must return every
undamaged frame with the same values, drop every damaged one, keep the text
lines, and agree with the C signal table.
"""
import os
import struct
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import console_proto as cp  # noqa: E402

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


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: console_test.py PATH/TO/proto_stream_gen")
    GEN = sys.argv.pop(1)
    unittest.main(verbosity=1)
