"""Telemetry / command protocol of the PMSM firmware, host side.

Mirrors firmware/telemetry_frame.c and firmware/telemetry.c (PROTOCOL.md):
COBS framing with 0x00 delimiters, CRC-16/CCITT-FALSE (high byte first),
SAMPLE and META frames, and a stream decoder that separates text response
lines from binary frames on the shared UART byte stream.
Standard library only (struct, binascii), so it runs without numpy or pyserial.
"""
import binascii
import struct

TYPE_SAMPLE = 0x01
TYPE_META = 0x02
HDR_SIZE = 7
CRC_SIZE = 2
VALUES_MAX = 32
PAYLOAD_MAX = HDR_SIZE + 8 + 4 * VALUES_MAX + CRC_SIZE
WIRE_MAX = PAYLOAD_MAX + PAYLOAD_MAX // 254 + 1 + 2

# Same order as tel_sig_t in firmware/telemetry.h: (name, SI unit after scaling).
SIGNALS = [
    ("i_a", "A"), ("i_b", "A"), ("i_d", "A"), ("i_q", "A"),
    ("psi", "Wb"), ("psi_ref", "Wb"),
    ("torque", "N*m"), ("torque_ref", "N*m"),
    ("speed", "r/min"), ("speed_ref", "r/min"),
    ("vector", ""), ("duty", ""), ("vdc", "V"), ("theta", "rad"),
    ("sector", ""), ("state", ""), ("fault", ""), ("cycles", ""),
    ("cm_step", ""), ("cm_progress", ""),
    ("torque_max", "N*m"), ("fieldweak_limit", ""),
    # an image with the injection (CMake option PMSM_SL_HFI) only
    ("sl_state", ""), ("angle_err", "rad"),
]


def signal_names(mask):
    """Names of the signals of a mask, in frame order (ascending bit)."""
    out = []
    for i in range(32):
        if mask & (1 << i):
            out.append(SIGNALS[i][0] if i < len(SIGNALS) else "sig%d" % i)
    return out


def crc16(data, crc=0xFFFF):
    """CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, xorout 0.
    The standard library's binascii.crc_hqx is this CRC with a given start value."""
    return binascii.crc_hqx(bytes(data), crc)


def cobs_encode(data):
    out = bytearray([0])
    code_pos = 0
    code = 1
    for i, b in enumerate(data):
        if b == 0:
            out[code_pos] = code
            code_pos = len(out)
            out.append(0)
            code = 1
        else:
            out.append(b)
            code += 1
            if code == 0xFF and i + 1 < len(data):
                out[code_pos] = code
                code_pos = len(out)
                out.append(0)
                code = 1
    out[code_pos] = code
    return bytes(out)


def cobs_decode(data):
    """Decode one COBS block sequence (no delimiter). None if malformed."""
    out = bytearray()
    i = 0
    n = len(data)
    while i < n:
        code = data[i]
        i += 1
        if code == 0 or i + code - 1 > n:
            return None
        blk = data[i:i + code - 1]
        if 0 in blk:
            return None
        out += blk
        i += code - 1
        if code != 0xFF and i < n:
            out.append(0)
    return bytes(out)


class Frame:
    __slots__ = ("type", "seq", "mask", "tick", "fs_hz", "every", "values", "scales")

    def __init__(self):
        self.type = 0
        self.seq = 0
        self.mask = 0
        self.tick = 0
        self.fs_hz = 0
        self.every = 0
        self.values = []
        self.scales = []

    def __repr__(self):
        if self.type == TYPE_META:
            return "Meta(seq=%d mask=0x%x fs=%d every=%d scales=%r)" % (
                self.seq, self.mask, self.fs_hz, self.every, self.scales)
        return "Sample(seq=%d mask=0x%x tick=%d values=%r)" % (
            self.seq, self.mask, self.tick, self.values)


def payload_size(ftype, mask):
    if ftype not in (TYPE_SAMPLE, TYPE_META):
        return 0
    extra = 4 if ftype == TYPE_SAMPLE else 8
    return HDR_SIZE + extra + 4 * bin(mask).count("1") + CRC_SIZE


def frame_parse(p):
    """Parse a decoded payload; None unless CRC, type and length all match."""
    if len(p) < HDR_SIZE + CRC_SIZE or crc16(p) != 0:
        return None
    ftype, seq, mask = struct.unpack_from("<BHI", p, 0)
    if payload_size(ftype, mask) != len(p):
        return None
    f = Frame()
    f.type, f.seq, f.mask = ftype, seq, mask
    n = bin(mask).count("1")
    if ftype == TYPE_SAMPLE:
        f.tick = struct.unpack_from("<I", p, 7)[0]
        f.values = list(struct.unpack_from("<%di" % n, p, 11))
    else:
        f.fs_hz, f.every = struct.unpack_from("<II", p, 7)
        f.scales = list(struct.unpack_from("<%df" % n, p, 15))
    return f


def frame_serialise(f):
    n = bin(f.mask).count("1")
    p = struct.pack("<BHI", f.type, f.seq, f.mask)
    if f.type == TYPE_SAMPLE:
        p += struct.pack("<I%di" % n, f.tick, *f.values)
    else:
        p += struct.pack("<II%df" % n, f.fs_hz, f.every, *f.scales)
    c = crc16(p)
    return p + bytes([c >> 8, c & 0xFF])


def frame_encode(f):
    return b"\x00" + cobs_encode(frame_serialise(f)) + b"\x00"


def _is_text(b):
    return 0x20 <= b <= 0x7E or b in (0x09, 0x0A, 0x0D)


class StreamDecoder:
    """Splits the UART byte stream into text lines and frames.

    feed(bytes) returns a list of events: ("text", str) for a response line,
    ("frame", Frame) for a valid frame, ("bad", bytes) for a dropped chunk.
    Same rules as tel_dec_feed: a chunk between 0x00 delimiters is a frame if
    COBS, CRC and length check; a printable run ending in LF (>= 2 bytes) is a
    text line; anything else is dropped and counted.
    """

    def __init__(self):
        self.buf = bytearray()
        self.all_text = True
        self.overflow = False
        self.frames = 0
        self.bad = 0
        self.text = 0

    def _reset(self):
        self.buf = bytearray()
        self.all_text = True
        self.overflow = False

    def feed(self, data):
        ev = []
        for b in data:
            if b != 0:
                if not _is_text(b):
                    self.all_text = False
                if len(self.buf) < max(WIRE_MAX, 4096):
                    self.buf.append(b)
                else:
                    self.overflow = True
                if not self.all_text and len(self.buf) > WIRE_MAX:
                    self.overflow = True
                if b == 0x0A and self.all_text and len(self.buf) >= 2:
                    self.text += 1
                    ev.append(("text", self.buf.decode("ascii").rstrip("\r\n")))
                    self._reset()
                continue
            if not self.buf and not self.overflow:
                continue
            f = None
            if not self.overflow:
                p = cobs_decode(bytes(self.buf))
                if p is not None:
                    f = frame_parse(p)
            if f is not None:
                self.frames += 1
                ev.append(("frame", f))
            elif self.all_text:
                self.text += 1
                for line in self.buf.decode("ascii").splitlines():
                    if line:
                        ev.append(("text", line))
            else:
                self.bad += 1
                ev.append(("bad", bytes(self.buf)))
            self._reset()
        return ev


class Recorder:
    """Collects SAMPLE frames into rows of SI values using the last META frame."""

    def __init__(self):
        self.meta = None
        self.rows = []        # (seq, tick, [values])
        self.mask = None
        self.lost = 0         # frames missing according to seq gaps
        self._last_seq = None

    def add(self, f):
        if self._last_seq is not None:
            self.lost += (f.seq - self._last_seq - 1) & 0xFFFF
        self._last_seq = f.seq
        if f.type == TYPE_META:
            self.meta = f
            return
        if self.mask is None:
            self.mask = f.mask
        if f.mask != self.mask:
            return  # a new stream with other signals: keep the first one
        self.rows.append((f.seq, f.tick, f.values))

    def scales(self):
        if self.meta is not None and self.meta.mask == self.mask:
            return [s if s != 0.0 else 1.0 for s in self.meta.scales]
        return [1.0] * bin(self.mask or 0).count("1")

    def write_csv(self, path):
        names = signal_names(self.mask or 0)
        sc = self.scales()
        fs = self.meta.fs_hz if self.meta is not None else 0
        t0 = self.rows[0][1] if self.rows else 0
        with open(path, "w") as fh:
            fh.write("seq,tick,time_s," + ",".join(names) + "\n")
            for seq, tick, vals in self.rows:
                t = ((tick - t0) & 0xFFFFFFFF) / fs if fs else float("nan")
                fh.write("%d,%d,%.9g," % (seq, tick, t))
                fh.write(",".join("%.9g" % (v * s) for v, s in zip(vals, sc)) + "\n")
        return len(self.rows)
