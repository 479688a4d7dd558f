#!/usr/bin/env python3
"""The PC's link faults, each named, exit status 1, no metrics file left:
a target that never answers (time-out), one that echoes (format), one that
exits (closed), one that computes from another ADC reading in one period
(target diverged, at that period), and a device that is no serial port.

  pil_faults.py --sim SIM --machine INI --target-host PROGRAM
"""
import argparse
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--target-host", required=True)
    a = ap.parse_args()
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        silent = os.path.join(tmp, "silent.sh")
        with open(silent, "w") as f:
            f.write("#!/bin/sh\nexec sleep 20\n")
        os.chmod(silent, 0o755)
        metrics = os.path.join(tmp, "m.json")
        base = [a.sim, "--machine", a.machine, "--controller", "m2ptfc", "--speed-rpm", "750",
                "--torque-ref", "1.8", "--duration", "0.1", "--metrics", metrics]
        cases = [
            ("silent target", ["--target", "exec:" + silent, "--link-timeout-ms", "100"], {},
             "link time-out (frame lost or late): no READY frame within 1000 ms"),
            ("echoing target", ["--target", "exec:/bin/cat"], {},
             "link format error (bad framing, type or length): type 0x21 instead of READY"),
            ("exiting target", ["--target", "exec:/bin/true"], {}, "link closed"),
            # period 600 is after the 256 calibration periods: running, gates on
            ("diverging target", ["--target", "exec:" + a.target_host],
             {"PIL_TARGET_FLIP_ADC_AT": "600"}, "target diverged from the host firmware at period 599"),
            ("not a serial port", ["--target", "board:/dev/null"], {}, "not a serial port"),
        ]
        for name, args, env, want in cases:
            e = dict(os.environ)
            e.update(env)
            p = subprocess.run(base + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env=e, timeout=120)
            ok = p.returncode == 1 and want in p.stderr and not os.path.exists(metrics)
            print("%s %s: exit %d, %s" % ("ok  " if ok else "FAIL", name, p.returncode,
                                          p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "(no message)"))
            if not ok:
                bad += 1
                print("     expected exit 1, no metrics file, and: " + want)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
