#!/usr/bin/python3
"""The simulator's report of the non-ideal mechanics (sim --metrics: mech_*).

On the thesis SPMSM's stress case (sim_host/machines/nonideal/
thesis_spmsm_stress.ini: stiction 0.36, Coulomb 0.24, passive load 0.48 N*m,
cogging 0.24 N*m peak, B = 3.82e-4 N*m*s/rad), free mechanics:
- torque mode, 0.5 N*m requested: the break-away is 0.36 + 0.48 = 0.84 N*m and
  the cogging adds at most 0.24, so the rotor stays at rest the whole window:
  mech_stuck_frac = 1, no break-away, no angle turned (friction torque n/a);
- speed mode, 300 r/min: turning the whole window, the bearings' mean torque
  over the angle is T_c + B <w^2>/<w> (0.252 N*m; the speed's ripple under the
  cogging puts <w^2>/<w> above <w> by its variance over the mean: within 2 %),
  the load's is the passive 0.48 N*m exactly, the friction power their
  product with the mean speed;
- a machine file without non-ideal mechanics writes no mech_* key.
usage: sim_mech_report_test.py SIM
"""
import json
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
STRESS = os.path.join(ROOT, "sim_host", "machines", "nonideal", "thesis_spmsm_stress.ini")
PLAIN = os.path.join(ROOT, "sim_host", "machines", "thesis_spmsm.ini")


def run(sim, machine, args, d):
    out = os.path.join(d, "m.json")
    r = subprocess.run([sim, "--machine", machine, "--controller", "foc", "--free",
                        "--metrics", out] + args, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("sim failed (%d): %s" % (r.returncode, r.stderr))
    with open(out) as f:
        return json.load(f), r.stdout


def main():
    sim = sys.argv[1]
    bad = 0

    def expect(cond, what):
        nonlocal bad
        print(("ok   " if cond else "FAIL ") + what)
        bad += 0 if cond else 1

    with tempfile.TemporaryDirectory() as d:
        m, out = run(sim, STRESS, ["--torque-ref", "0.5", "--duration", "0.3"], d)
        expect(m["mech_stuck_frac"] == 1.0, "held below break-away: stuck fraction %r"
               % m["mech_stuck_frac"])
        expect(m["mech_breakaways"] == 0 and m["mech_stops"] == 0, "no break-away, no stop")
        expect(m["mech_friction_torque_nm"] is None, "no angle turned: friction torque n/a")
        expect("mechanics: at rest (held by friction)" in out, "summary line printed")

        m, out = run(sim, STRESS, ["--speed-ref-rpm", "300", "--duration", "0.6"], d)
        w = m["speed_mean_rpm"] * 2.0 * math.pi / 60.0
        expect(abs(m["speed_mean_rpm"] - 300.0) < 6.0, "speed %.1f r/min" % m["speed_mean_rpm"])
        tf = 0.24 + 3.81972e-4 * w
        expect(m["mech_stuck_frac"] == 0.0, "turning all the window")
        expect(abs(m["mech_friction_torque_nm"] - tf) < 0.02 * 3.81972e-4 * w + 1e-9,
               "friction %.6f N*m, T_c + B w = %.6f" % (m["mech_friction_torque_nm"], tf))
        expect(abs(m["mech_load_torque_nm"] - 0.48) < 1e-9,
               "passive load %.9f N*m" % m["mech_load_torque_nm"])
        expect(abs(m["mech_friction_power_w"] - tf * w) < 0.03 * tf * w,
               "friction power %.4f W, about %.4f" % (m["mech_friction_power_w"], tf * w))

        m, out = run(sim, PLAIN, ["--speed-ref-rpm", "300", "--duration", "0.2"], d)
        expect(not any(k.startswith("mech_") for k in m), "no mech_* keys without them")
        expect("mechanics:" not in out, "no summary line without them")
    print("sim_mech_report: %d failures" % bad)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
