#!/usr/bin/env python3
"""Processor in the loop against the host: the same ./tools/sim run with the
firmware on the host and on a target (--target qemu or exec:PROGRAM) must
give the same exit status and metrics JSON, every field equal (the plant is
the PC's in both; the target's compare values and gate requests drive it).

  pil_equiv.py --sim SIM --machine INI --target T [--pil-image ELF] CASE...
  CASE: NAME=ARGS, ARGS the sim options of the run (quoted, space separated);
        @FILE in ARGS is FILE in this folder (scenario files)
Prints per case: the fields compared, the wall time of each side and the
target's wall time per simulated second. Exit 0 when every case agrees.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run(cmd):
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
    return p, time.monotonic() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--target", required=True)
    ap.add_argument("--pil-image")
    ap.add_argument("cases", nargs="+")
    a = ap.parse_args()
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for case in a.cases:
            name, _, args = case.partition("=")
            extra = [os.path.join(HERE, x[1:]) if x.startswith("@") else x
                     for x in shlex.split(args)]
            base = [a.sim, "--machine", a.machine] + extra
            mh = os.path.join(tmp, name + "_host.json")
            mt = os.path.join(tmp, name + "_target.json")
            ph, th = run(base + ["--metrics", mh])
            tgt = ["--target", a.target] + (["--pil-image", a.pil_image] if a.pil_image else [])
            pt, tt = run(base + ["--metrics", mt] + tgt)
            rate = [l for l in pt.stderr.splitlines() if l.startswith("sim: target")]
            why = None
            if ph.returncode != pt.returncode:
                why = "exit status host %d, target %d" % (ph.returncode, pt.returncode)
            elif ph.returncode not in (0, 3):
                why = "the host run failed (%d): %s" % (ph.returncode, ph.stderr.strip())
            else:
                jh = json.load(open(mh))
                jt = json.load(open(mt))
                diff = [k for k in sorted(set(jh) | set(jt)) if jh.get(k) != jt.get(k)]
                if diff:
                    why = "fields differ: " + ", ".join(
                        "%s host %r target %r" % (k, jh.get(k), jt.get(k)) for k in diff)
                elif ph.stdout != pt.stdout:
                    why = "the printed metrics differ"
            if why:
                bad += 1
                print("FAIL %s: %s" % (name, why))
                print(pt.stderr.strip())
            else:
                print("ok   %s: %d fields equal, exit %d; host %.2f s, target %.2f s wall"
                      % (name, len(jh), ph.returncode, th, tt))
            for l in rate:
                print("     " + l)
    print("%d of %d cases equal" % (len(a.cases) - bad, len(a.cases)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
