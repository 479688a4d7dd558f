#!/usr/bin/python3
"""sim_host/machines/gen_nonideal.py: unseen variants of the shipped machines.

For each base file and seeds 1..8 (with --spread 0.2): the machine loader
accepts the file (sim --list-tunables foc --machine FILE), every fraction of
the rated torque lies in [F/2, F] of the requested limit, stiction >= Coulomb,
the whole cogging torque's peak (all harmonics, evaluated here on 20000 points)
<= the limit; the same seed writes the same bytes; a fraction out of [0, 1] is
refused naming the option, the value and the range.
usage: gen_nonideal_test.py SIM
"""
import configparser
import filecmp
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MDIR = os.path.join(ROOT, "sim_host", "machines")
GEN = os.path.join(MDIR, "gen_nonideal.py")
LIMITS = {"stiction": 0.15, "coulomb": 0.10, "viscous": 0.05, "cogging": 0.10, "passive": 0.20}
BASES = ["thesis_spmsm", "mj5208_drone", "gbm5208_gimbal", "outrunner_24v", "gimbal_12v",
         "chapter_ipmsm"]


def gen(base, out, seed, extra=()):
    args = [sys.executable, GEN, os.path.join(MDIR, base + ".ini"), out]
    for k, v in LIMITS.items():
        args += ["--" + k, str(v)]
    if seed is not None:
        args += ["--seed", str(seed), "--spread", "0.2"]
    return subprocess.run(args + list(extra), capture_output=True, text=True)


def fails(msg):
    print("FAIL: " + msg)
    return 1


def check(path, sim):
    bad = 0
    r = subprocess.run([sim, "--list-tunables", "foc", "--machine", path], capture_output=True,
                       text=True)
    if r.returncode != 0:
        return fails("%s not loaded: %s" % (path, r.stderr.strip()))
    c = configparser.ConfigParser(inline_comment_prefixes=(";",))
    c.read(path)
    m, rated = c["mechanics"], c["rated"]
    t = float(rated["torque_nm"])
    w = float(rated["speed_rpm"]) * 2.0 * math.pi / 60.0
    got = {"stiction": float(m["stiction_nm"]) / t, "coulomb": float(m["coulomb_nm"]) / t,
           "viscous": float(m["friction_nms"]) * w / t, "passive": float(m["load_nm"]) / t}
    amps = [float(m["cogging_nm"])] + [float(x) for x in m.get("cogging_harmonics_nm", "").split()]
    phs = [float(m["cogging_phase_deg"])] + [float(x) for x in
                                             m.get("cogging_harmonics_deg", "").split()]
    peak = max(abs(sum(a * math.sin((k + 1) * x + math.radians(p))
                       for k, (a, p) in enumerate(zip(amps, phs))))
               for x in (2.0 * math.pi * i / 20000 for i in range(20000)))
    got["cogging"] = peak / t
    for k, lim in LIMITS.items():
        lo = 0.5 * lim if k != "stiction" else min(0.5 * lim, got["coulomb"])
        if not (lo * (1 - 1e-5) <= got[k] <= lim * (1 + 1e-4)):
            bad += fails("%s: %s = %.6g outside [%.6g, %.6g]" % (path, k, got[k], lo, lim))
    if got["stiction"] < got["coulomb"]:
        bad += fails("%s: stiction below Coulomb" % path)
    return bad


def main():
    sim = sys.argv[1]
    bad, n = 0, 0
    with tempfile.TemporaryDirectory() as d:
        for base in BASES:
            for seed in range(1, 9):
                out = os.path.join(d, "%s_%d.ini" % (base, seed))
                r = gen(base, out, seed, ("--slots", "12") if base == "chapter_ipmsm" else ())
                if r.returncode != 0:
                    bad += fails("%s seed %d: %s" % (base, seed, r.stderr.strip()))
                    continue
                bad += check(out, sim)
                n += 1
        again = os.path.join(d, "again.ini")
        gen("mj5208_drone", again, 5)
        if not filecmp.cmp(again, os.path.join(d, "mj5208_drone_5.ini"), shallow=False):
            bad += fails("seed 5 did not reproduce its file")
        r = gen("mj5208_drone", os.path.join(d, "x.ini"), None, ("--coulomb", "1.5"))
        if r.returncode == 0 or "--coulomb = 1.5 out of range [0, 1]" not in r.stderr:
            bad += fails("--coulomb 1.5 not refused by name: %r" % r.stderr)
    print("gen_nonideal: %d variants checked, %d failures" % (n, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
