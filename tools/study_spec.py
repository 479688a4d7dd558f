"""Declarative studies (tools/study): a TOML file names machines, controllers,
operating points, the production spread of the motor and drive (distributions
with their seed), durations and metrics; this module checks it, expands it into
simulator runs (tools/study_engine.py) and writes the table and the report.

File format (docs/studies.md; tools/studies/tolerance.toml is the shipped study):

  [study]     name, title, seed, samples, controllers, duration_s, window_s, metrics
  [machines]  KEY = "file.ini"   (a bare name: sim_host/machines/; else relative
              to the study file)
  [[points]]  mode = "torque": speed_pu | speed_rpm, torque_pu | torque_nm
              mode = "speed":  speed_pu | speed_rpm, load_pu | load_nm, step_s
              (optional name, duration_s, window_s)
  [spread]    PARAMETER = { dist = "uniform", lo = L, hi = H }
                        | { dist = "normal", sd = S, lo = L, hi = H [, mean = M] }
                        | { dist = "fixed", value = V }
  [drive]     comp_dead_time_ns: the dead time the firmware compensates

Each machine gets `samples` units drawn from the spread and a nominal unit 0
(every distribution at its centre: the machine file itself for a symmetric
relative spread); every unit runs every controller at every point. The plant is the
unit; the controller is configured with the nominal machine file (what a
production drive knows). Draws are independent of order and workers: unit k's
value of a parameter comes from its own generator seeded (seed, machine, k,
parameter). The simulator's ADC-noise seed of unit k is seed + k.

Errors name the file, the line, the key and the value; tools/study exits 2.
"""
import configparser
import csv
import io
import math
import os
import re
import tomllib
import zlib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MDIR = os.path.join(ROOT, "sim_host", "machines")

# Spread parameters: (kind, domain lo, domain hi, what it does). rel: a relative
# deviation applied to the machine file's value (x (1 + d)); abs: the value itself.
PARAMS = {
    "rs": ("rel", -1.0, 10.0, "[machine] rs_ohm x (1 + d)"),
    "l": ("rel", -1.0, 10.0, "[machine] ld_mh and lq_mh x (1 + d), one draw for both"),
    "ld": ("rel", -1.0, 10.0, "[machine] ld_mh x (1 + d)"),
    "lq": ("rel", -1.0, 10.0, "[machine] lq_mh x (1 + d)"),
    "psi_pm": ("rel", -1.0, 10.0, "[machine] psi_pm_wb x (1 + d)"),
    "inertia": ("rel", -1.0, 100.0, "[mechanics] inertia_kgm2 x (1 + d)"),
    "friction_nms": ("abs", 0.0, 1e6, "[mechanics] friction_nms"),
    "encoder_offset_deg": ("abs", -180.0, 180.0,
                           "[sensors] encoder_offset_deg of the plant (electrical degrees; "
                           "the drive is configured with the nominal 0)"),
    "dead_time_ns": ("abs", 0.0, 1e5, "[inverter] dead_time_ns of the plant"),
    "current_gain": ("abs", -0.25, 0.25, "--current-gain-err: one draw per phase"),
}
# Which machine-file keys a parameter scales.
REL_KEYS = {"rs": [("machine", "rs_ohm")], "l": [("machine", "ld_mh"), ("machine", "lq_mh")],
            "ld": [("machine", "ld_mh")], "lq": [("machine", "lq_mh")],
            "psi_pm": [("machine", "psi_pm_wb")], "inertia": [("mechanics", "inertia_kgm2")]}
ABS_KEYS = {"friction_nms": ("mechanics", "friction_nms"),
            "encoder_offset_deg": ("sensors", "encoder_offset_deg"),
            "dead_time_ns": ("inverter", "dead_time_ns")}
DISTS = {"uniform": {"lo", "hi"}, "normal": {"sd", "lo", "hi", "mean"}, "fixed": {"value"}}


def _m_torque_err(m, pt):
    t = m.get("torque_mean_nm")
    return None if t is None else 100.0 * (t / pt["torque_nm"] - 1.0)


def _m_ripple(m, pt):
    r = m.get("torque_ripple_nm")
    return None if r is None else 100.0 * r / pt["torque_rated_nm"]


def _m_speed(key):
    def f(m, pt):
        e = m.get(key)
        return None if e is None else 100.0 * e / abs(pt["speed_rpm"])
    return f


# Metrics: (modes, function(metrics JSON, point) -> value, unit, what, "abs" if the
# worst case is the largest magnitude else the largest value).
METRICS = {
    "torque_err_pct": (("torque",), _m_torque_err, "%",
                       "mean torque against the reference, % of the reference", "abs"),
    "torque_ripple_pct": (("torque",), _m_ripple, "% of rated",
                          "torque ripple (standard deviation), % of the rated torque", "max"),
    "speed_err_max_pct": (("speed",), _m_speed("speed_err_max_rpm"), "%",
                          "largest speed error after the load step, % of the speed reference",
                          "max"),
    "speed_err_rms_pct": (("speed",), _m_speed("speed_err_rms_rpm"), "%",
                          "rms speed error over the window, % of the speed reference", "max"),
}
STUDY_KEYS = {"name", "title", "seed", "samples", "controllers", "duration_s", "window_s",
              "metrics"}
POINT_KEYS = {"name", "mode", "speed_pu", "speed_rpm", "torque_pu", "torque_nm", "load_pu",
              "load_nm", "step_s", "duration_s", "window_s"}
DRIVE_KEYS = {"comp_dead_time_ns"}


class SpecError(Exception):
    pass


# ---------------------------------------------------------------- lines of a TOML file

def toml_lines(text):
    """{dotted key path: line number} of a TOML text: table headers, keys (dotted
    too) and the keys of one-line inline tables; arrays of tables get their index."""
    lines, table, aot = {}, [], {}
    key_re = r'(?:[A-Za-z0-9_-]+|"[^"]*"|\'[^\']*\')'
    for n, raw in enumerate(text.splitlines(), 1):
        s = raw.strip()
        if not s or s.startswith("#"):
            continue
        m = re.match(r"^\[\[\s*(.+?)\s*\]\]", s)
        if m:
            base = tuple(p.strip().strip('"\'') for p in m.group(1).split("."))
            aot[base] = aot.get(base, -1) + 1
            table = list(base) + [str(aot[base])]
            lines.setdefault(".".join(table), n)
            continue
        m = re.match(r"^\[\s*(.+?)\s*\]", s)
        if m:
            table = [p.strip().strip('"\'') for p in m.group(1).split(".")]
            lines.setdefault(".".join(table), n)
            continue
        m = re.match(rf"^({key_re}(?:\s*\.\s*{key_re})*)\s*=\s*(.*)$", s)
        if m:
            k = [p.strip().strip('"\'') for p in m.group(1).split(".")]
            path = table + k
            lines.setdefault(".".join(path), n)
            rest = m.group(2)
            if rest.startswith("{"):
                for ik in re.findall(rf"(?:^\{{|,)\s*({key_re})\s*=", rest):
                    lines.setdefault(".".join(path + [ik.strip('"\'')]), n)
    return lines


class Spec:
    """A checked study file."""

    def __init__(self, path):
        self.path = path
        self.dir = os.path.dirname(os.path.abspath(path))
        try:
            with open(path, "rb") as f:
                raw = f.read()
        except OSError as e:
            raise SpecError(f"{path}: {e.strerror}") from None
        try:
            text = raw.decode("utf-8")
            self.doc = tomllib.loads(text)
        except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
            raise SpecError(f"{path}: not a valid TOML file: {e}") from None
        self.lines = toml_lines(text)
        self._check()

    # -- errors
    def where(self, *path):
        """file:line of the most specific key of path that has a line."""
        p = [str(x) for x in path]
        while p:
            n = self.lines.get(".".join(p))
            if n:
                return f"{self.path}:{n}"
            p.pop()
        return self.path

    def err(self, path, msg):
        name = ".".join(str(x) for x in path)
        return SpecError(f"{self.where(*path)}: {name}: {msg}")

    def _known(self, table, path, allowed):
        for k in table:
            if k not in allowed:
                raise self.err(path + [k], f"unknown key (allowed: {', '.join(sorted(allowed))})")

    def _num(self, v, path, lo=None, hi=None, lo_open=False, integer=False):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and
                                                                      not isinstance(v, int)):
            raise self.err(path, f"{v!r} is not {'a whole number' if integer else 'a number'}")
        if not math.isfinite(v):
            raise self.err(path, f"{v!r} is not finite")
        if (lo is not None and (v <= lo if lo_open else v < lo)) or (hi is not None and v > hi):
            rng = f"{'(' if lo_open else '['}{lo if lo is not None else '-inf'}, " \
                  f"{hi if hi is not None else 'inf'}]"
            raise self.err(path, f"{v!r} is outside the allowed range {rng}")
        return v

    # -- the check
    def _check(self):
        d = self.doc
        self._known(d, [], {"study", "machines", "points", "spread", "drive"})
        for k in ("study", "machines", "points"):
            if k not in d:
                raise SpecError(f"{self.path}: missing [{k}]" if k != "points" else
                                f"{self.path}: missing [[points]] (at least one operating point)")
        st = d["study"]
        if not isinstance(st, dict):
            raise self.err(["study"], "must be a table")
        self._known(st, ["study"], STUDY_KEYS)
        for k in ("name", "seed", "samples", "controllers", "duration_s"):
            if k not in st:
                raise self.err(["study"], f"missing key '{k}'")
        if not isinstance(st["name"], str) or not re.fullmatch(r"[A-Za-z0-9_-]+", st["name"]):
            raise self.err(["study", "name"], f"{st['name']!r}: letters, digits, _ and - only "
                                              "(it names the report's files)")
        self.name = st["name"]
        self.title = st.get("title", self.name)
        self.seed = self._num(st["seed"], ["study", "seed"], 0, 2 ** 32 - 1, integer=True)
        self.samples = self._num(st["samples"], ["study", "samples"], 0, 10 ** 6, integer=True)
        c = st["controllers"]
        if not isinstance(c, list) or not c or not all(isinstance(x, str) for x in c):
            raise self.err(["study", "controllers"], f"{c!r}: a non-empty list of names")
        if len(set(c)) != len(c):
            raise self.err(["study", "controllers"], f"{c!r}: a controller named twice")
        self.controllers = c
        self.duration = self._num(st["duration_s"], ["study", "duration_s"], 0, 100, lo_open=True)
        self.window = self._window(st.get("window_s"), ["study", "window_s"], self.duration)
        mets = st.get("metrics", list(METRICS))
        if not isinstance(mets, list) or not mets:
            raise self.err(["study", "metrics"], f"{mets!r}: a non-empty list")
        for i, m in enumerate(mets):
            if m not in METRICS:
                raise self.err(["study", "metrics"], f"unknown metric {m!r} (known: "
                                                     f"{', '.join(METRICS)})")
        self.metrics = mets
        # machines
        ms = d["machines"]
        if not isinstance(ms, dict) or not ms:
            raise self.err(["machines"], "a table of KEY = \"file.ini\" with at least one entry")
        self.machines = {}
        for k, v in ms.items():
            if not isinstance(v, str):
                raise self.err(["machines", k], f"{v!r} is not a file name")
            p = os.path.join(MDIR, v) if os.sep not in v else os.path.join(self.dir, v)
            if not os.path.isfile(p):
                raise self.err(["machines", k], f"machine file {v!r} not found ({p})")
            self.machines[k] = Machine(k, p, self, ["machines", k])
        # points
        pts = d["points"]
        if not isinstance(pts, list) or not pts:
            raise SpecError(f"{self.path}: [[points]]: at least one operating point")
        self.points = [self._point(p, i) for i, p in enumerate(pts)]
        # spread
        sp = d.get("spread", {})
        if not isinstance(sp, dict):
            raise self.err(["spread"], "must be a table")
        self.spread = {}
        for k, v in sp.items():
            if k not in PARAMS:
                raise self.err(["spread", k], f"unknown parameter (known: {', '.join(PARAMS)})")
            self.spread[k] = self._dist(v, ["spread", k], PARAMS[k])
        if "l" in self.spread and ({"ld", "lq"} & set(self.spread)):
            raise self.err(["spread", "l"], "give either l (Ld and Lq together) or ld/lq")
        dr = d.get("drive", {})
        if not isinstance(dr, dict):
            raise self.err(["drive"], "must be a table")
        self._known(dr, ["drive"], DRIVE_KEYS)
        self.comp_dead_time_ns = (None if "comp_dead_time_ns" not in dr else
                                  self._num(dr["comp_dead_time_ns"], ["drive", "comp_dead_time_ns"],
                                            0, 1e5))

    def _window(self, w, path, duration):
        if w is None:
            return (duration / 3.0, duration)
        if (not isinstance(w, list) or len(w) != 2 or
                not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in w)):
            raise self.err(path, f"{w!r}: expected [start, end] in seconds")
        if not 0 <= w[0] < w[1] <= duration:
            raise self.err(path, f"{w!r}: need 0 <= start < end <= duration ({duration:g} s)")
        return (float(w[0]), float(w[1]))

    def _point(self, p, i):
        path = ["points", i]
        if not isinstance(p, dict):
            raise self.err(path, "must be a table")
        self._known(p, path, POINT_KEYS)
        mode = p.get("mode")
        if mode not in ("torque", "speed"):
            raise self.err(path + ["mode"], f"{mode!r}: expected \"torque\" or \"speed\"")
        allowed = ({"speed_pu", "speed_rpm", "torque_pu", "torque_nm"} if mode == "torque" else
                   {"speed_pu", "speed_rpm", "load_pu", "load_nm", "step_s"})
        for k in p:
            if k in POINT_KEYS - {"name", "mode", "duration_s", "window_s"} and k not in allowed:
                raise self.err(path + [k], f"does not apply to a {mode}-mode point (its keys: "
                                           f"{', '.join(sorted(allowed))})")

        def one_of(a, b, lo, hi):
            if (a in p) == (b in p):
                raise self.err(path, f"give exactly one of {a} and {b}")
            k = a if a in p else b
            return k, self._num(p[k], path + [k], lo, hi)

        pt = {"mode": mode, "index": i}
        pt["speed"] = one_of("speed_pu", "speed_rpm", -10, 10) if "speed_pu" in p else \
            one_of("speed_pu", "speed_rpm", -1e5, 1e5)
        if pt["speed"][1] == 0 and mode == "speed":
            raise self.err(path, "a speed-mode point needs a speed other than 0 (its error is "
                                 "relative to the reference)")
        dur = self._num(p.get("duration_s", self.duration), path + ["duration_s"], 0, 100,
                        lo_open=True)
        pt["duration_s"] = dur
        if mode == "torque":
            pt["torque"] = one_of("torque_pu", "torque_nm", -10, 10) if "torque_pu" in p else \
                one_of("torque_pu", "torque_nm", -1e5, 1e5)
            if pt["torque"][1] == 0:
                raise self.err(path, "a torque-mode point needs a torque other than 0 (its error "
                                     "is relative to the reference)")
            win = p.get("window_s")
            pt["window_s"] = (self._window(win, path + ["window_s"], dur) if win is not None
                              else self._window_clip(self.window, dur, path))
        else:
            pt["load"] = one_of("load_pu", "load_nm", -10, 10) if "load_pu" in p else \
                one_of("load_pu", "load_nm", -1e5, 1e5)
            if "step_s" not in p:
                raise self.err(path, "a speed-mode point needs step_s (the load step's time)")
            pt["step_s"] = self._num(p["step_s"], path + ["step_s"], 0, dur, lo_open=True)
            win = p.get("window_s")
            pt["window_s"] = (self._window(win, path + ["window_s"], dur) if win is not None
                              else (pt["step_s"], dur))
        pt["name"] = p.get("name")
        if pt["name"] is not None and not isinstance(pt["name"], str):
            raise self.err(path + ["name"], f"{pt['name']!r} is not a text")
        return pt

    def _window_clip(self, w, dur, path):
        if w[1] > dur:
            raise self.err(path + ["duration_s"], f"{dur:g} s is shorter than [study] window_s "
                                                  f"{list(w)}: give the point its own window_s")
        return w

    def _dist(self, v, path, param):
        kind, dlo, dhi, _ = param
        if not isinstance(v, dict):
            raise self.err(path, f"{v!r}: expected {{ dist = \"uniform\", lo = .., hi = .. }}")
        dist = v.get("dist")
        if dist not in DISTS:
            raise self.err(path + ["dist"], f"{dist!r}: unknown distribution (known: "
                                            f"{', '.join(DISTS)})")
        for k in v:
            if k != "dist" and k not in DISTS[dist]:
                raise self.err(path + [k], f"not a parameter of a {dist} distribution (its: "
                                           f"{', '.join(sorted(DISTS[dist]))})")
        vals = {k: self._num(x, path + [k]) for k, x in v.items() if k != "dist"}
        need = {"uniform": ("lo", "hi"), "normal": ("sd", "lo", "hi"), "fixed": ("value",)}[dist]
        for k in need:
            if k not in vals:
                raise self.err(path, f"a {dist} distribution needs {k}" +
                               (" (the truncation bounds: a normal's support must lie in the "
                                "parameter's domain)" if dist == "normal" and k != "sd" else ""))
        what = "deviation" if kind == "rel" else "value"
        dom = f"({dlo:g}, {dhi:g}]" if kind == "rel" else f"[{dlo:g}, {dhi:g}]"

        def inside(x):
            return (dlo < x <= dhi) if kind == "rel" else (dlo <= x <= dhi)

        if dist == "fixed":
            if not inside(vals["value"]):
                raise self.err(path + ["value"], f"{vals['value']!r} is outside the parameter's "
                                                 f"domain: a {what} in {dom}")
            return {"dist": dist, **vals}
        if not vals["lo"] < vals["hi"]:
            raise self.err(path + ["hi"], f"lo {vals['lo']!r} >= hi {vals['hi']!r}: an empty "
                                          "distribution")
        for k in ("lo", "hi"):
            if not inside(vals[k]):
                raise self.err(path + [k], f"{vals[k]!r} is outside the parameter's domain: a "
                                           f"{what} in {dom}"
                               + (" (the quantity would not be positive)" if kind == "rel"
                                  and vals[k] <= dlo else ""))
        if dist == "normal":
            if vals["sd"] <= 0:
                raise self.err(path + ["sd"], f"{vals['sd']!r}: a standard deviation > 0")
            mean = vals.get("mean", 0.0)
            if not vals["lo"] <= mean <= vals["hi"]:
                raise self.err(path + ["mean"], f"{mean!r} lies outside [lo, hi] = "
                                                f"[{vals['lo']!r}, {vals['hi']!r}]")
            vals["mean"] = mean
        return {"dist": dist, **vals}


class Machine:
    """A machine file and what the points need of it."""

    def __init__(self, key, path, spec, where):
        self.key, self.path = key, path
        with open(path) as f:
            self.text = f.read()
        cp = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
        try:
            cp.read_string(self.text)
            self.name = cp.get("machine", "name")
            self.speed_rated = cp.getfloat("rated", "speed_rpm")
            self.torque_rated = cp.getfloat("rated", "torque_nm")
        except (configparser.Error, ValueError) as e:
            raise spec.err(where, f"machine file {path}: {e}") from None


# ---------------------------------------------------------------- draws and runs

def _stable(s):
    return zlib.crc32(s.encode())


def centre(dist):
    """The nominal value of a distribution: the middle of its range, its mean."""
    return float({"uniform": lambda d: (d["lo"] + d["hi"]) / 2.0, "normal": lambda d: d["mean"],
                  "fixed": lambda d: d["value"]}[dist["dist"]](dist))


def draw(spec, machine_key, unit, param, dist, n=1):
    """n values of param for unit (unit 0: the nominal unit, every distribution's
    centre)."""
    if unit == 0:
        return [centre(dist)] * n
    rng = np.random.default_rng([spec.seed, _stable(machine_key), unit, _stable(param)])
    out = []
    for _ in range(n):
        if dist["dist"] == "fixed":
            out.append(float(dist["value"]))
        elif dist["dist"] == "uniform":
            out.append(float(dist["lo"] + (dist["hi"] - dist["lo"]) * rng.random()))
        else:
            while True:  # truncated normal by rejection (bounds hold >= 1e-3 of the mass)
                x = float(rng.normal(dist["mean"], dist["sd"]))
                if dist["lo"] <= x <= dist["hi"]:
                    out.append(x)
                    break
    return out


def unit_params(spec, mkey, unit):
    """{parameter: value} of a unit; current_gain a tuple of three."""
    out = {}
    for p, dist in spec.spread.items():
        out[p] = tuple(draw(spec, mkey, unit, p, dist, 3)) if p == "current_gain" else \
            draw(spec, mkey, unit, p, dist)[0]
    return out


def machine_variant(text, params):
    """The machine file's text with the unit's parameters applied."""
    rel, absval = {}, {}
    for p, v in params.items():
        if p in REL_KEYS and v:
            for sk in REL_KEYS[p]:
                rel[sk] = v
        elif p in ABS_KEYS and v is not None:
            absval[ABS_KEYS[p]] = v
    lines, sec, seen = [], None, set()

    def flush_missing(section):
        for (s, k), v in absval.items():
            if s == section and (s, k) not in seen:
                lines.append(f"{k} = {v!r}\n")
                seen.add((s, k))

    for ln in text.splitlines(keepends=True):
        s = ln.strip()
        if s.startswith("["):
            flush_missing(sec)
            sec = s.strip("[]").strip()
        elif "=" in s and not s.startswith((";", "#")):
            k = s.split("=")[0].strip()
            if (sec, k) in rel:
                val = float(s.split("=", 1)[1].split(";")[0].split("#")[0])
                ln = f"{k} = {val * (1.0 + rel[(sec, k)])!r}\n"
            elif (sec, k) in absval:
                ln = f"{k} = {absval[(sec, k)]!r}\n"
                seen.add((sec, k))
        lines.append(ln if ln.endswith("\n") else ln + "\n")
    flush_missing(sec)
    for (s, k), v in absval.items():
        if (s, k) not in seen:
            lines.append(f"\n[{s}]\n{k} = {v!r}\n")
            seen.add((s, k))
    return "".join(lines)


def point_values(pt, m):
    """The point's speed (r/min), torque or load (N*m) on machine m."""
    k, v = pt["speed"]
    rpm = v * m.speed_rated if k == "speed_pu" else v
    out = {"speed_rpm": rpm, "torque_rated_nm": m.torque_rated}
    key = "torque" if pt["mode"] == "torque" else "load"
    k, v = pt[key]
    out[f"{key}_nm"] = v * m.torque_rated if k.endswith("_pu") else v
    return out


def point_label(pt, pv):
    if pt["name"]:
        return pt["name"]
    if pt["mode"] == "torque":
        return f"{pv['speed_rpm']:g} r/min, {pv['torque_nm']:.4g} N·m"
    return f"{pv['speed_rpm']:g} r/min, load step {pv['load_nm']:.4g} N·m"


class Case:
    """One run of the study: machine, unit, controller, point, its parameters."""

    def __init__(self, spec, mkey, unit, ctrl, pt, params):
        self.mkey, self.unit, self.ctrl, self.pt, self.params = mkey, unit, ctrl, pt, params
        m = spec.machines[mkey]
        self.machine = m
        self.pv = point_values(pt, m)
        self.label = point_label(pt, self.pv)

    def order(self, spec):
        return (list(spec.machines).index(self.mkey), spec.controllers.index(self.ctrl),
                self.pt["index"], self.unit)

    def tag(self):
        return f"{self.ctrl} {self.machine.name} {self.label} unit {self.unit}"


def expand(spec, build, samples=None):
    """[(Case, study_engine.Run)] of the study in its order."""
    import study_engine as se
    n = spec.samples if samples is None else samples
    out = []
    for mkey, m in spec.machines.items():
        for unit in range(n + 1):
            params = unit_params(spec, mkey, unit)
            plant = se.Text(f"{mkey}_unit{unit}.ini", machine_variant(m.text, params),
                            base_dir=os.path.dirname(m.path))
            for ctrl in spec.controllers:
                for pt in spec.points:
                    case = Case(spec, mkey, unit, ctrl, pt, params)
                    pv = case.pv
                    dur, win = pt["duration_s"], pt["window_s"]
                    args = ["--machine", plant, "--control-machine", m.path, "--controller", ctrl,
                            "--duration", repr(dur), "--window", f"{win[0]!r}:{win[1]!r}",
                            "--seed", spec.seed + unit]
                    if pt["mode"] == "torque":
                        args += ["--speed-rpm", repr(pv["speed_rpm"]), "--torque-ref",
                                 repr(pv["torque_nm"])]
                    else:
                        scn = se.Text("load_step.scn", f"at {pt['step_s']!r} load={pv['load_nm']!r}\n")
                        args += ["--free", "--speed-rpm", repr(pv["speed_rpm"]), "--speed-ref-rpm",
                                 repr(pv["speed_rpm"]), "--scenario", scn]
                    g = params.get("current_gain")
                    if g is not None and any(g):
                        args += ["--current-gain-err", ",".join(repr(x) for x in g)]
                    if spec.comp_dead_time_ns is not None:
                        args += ["--comp-dead-time-ns", repr(spec.comp_dead_time_ns)]
                    out.append((case, se.Run(build, args, tag=case.tag())))
    return out


# ---------------------------------------------------------------- the table

def param_columns(spec):
    cols = []
    for p in spec.spread:
        if p == "current_gain":
            cols += [f"current_gain_{x}" for x in "abc"]
        else:
            cols.append(p)
    return cols


def param_values(spec, case):
    vals = []
    for p in spec.spread:
        v = case.params.get(p)
        if p == "current_gain":
            vals += list(v)
        else:
            vals.append(v)
    return vals


def metric_values(spec, case, res):
    m = res.metrics if res.status == "ok" else None
    out = {}
    for k in spec.metrics:
        modes, fn = METRICS[k][0], METRICS[k][1]
        out[k] = fn(m, case.pv) if (m is not None and case.pt["mode"] in modes) else None
    return out


def table_csv(spec, rows):
    """The study's table: one row per run in the study's order; floats written with
    repr (the same bytes for the same results)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["machine", "controller", "point", "unit"] + param_columns(spec) +
               ["status", "reason"] + list(spec.metrics) + ["key"])

    def f(x):
        return "" if x is None else repr(x) if isinstance(x, float) else str(x)

    for case, res, mv in rows:
        w.writerow([case.machine.name, case.ctrl, case.label, case.unit] +
                   [f(x) for x in param_values(spec, case)] + [res.status, res.reason] +
                   [f(mv[k]) for k in spec.metrics] + [res.key])
    return buf.getvalue()
