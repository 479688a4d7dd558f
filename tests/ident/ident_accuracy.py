#!/usr/bin/python3
"""Identification accuracy on one shipped machine file against the accuracy bounds of docs/identification.md.

The simulated drive is the machine file with a realistic inverter (1 us dead
time, 1.2 V device drops - at most 2 % of the DC link: a 12-60 V drive switches
MOSFETs), the hal/sim ADC noise (0.5 count) and an encoder
whose offset and direction are not the defaults ([sensors] offset from the
file's name, direction -1). The firmware is configured with deliberately wrong
parameters (Rs x 1.3, Ld x 0.7, Lq x 0.8, psi_pm x 1.2, J x 2) and the default
encoder settings, so nothing it identifies can come from its configuration.

Checks (docs/identification.md, "Accuracy required"): |dRs| <= 2 %, |dLd|, |dLq| <= 5 %,
|dpsi_pm| <= 2 %, encoder offset within 2 deg electrical, the direction right,
the counts per revolution measured within 1 % and the file's lines exact, the
inertia within 10 %, the viscous and the Coulomb friction (the bearings' and a
passive load's) within 15 % where they are at least 1 % of the rated torque (at
the rated speed), else below that 1 %; at most 10 s of motor time, the true
phase current never above the rated current; on the thesis SPMSM also m2ptfc
and drr configured from the identified machine file: |T_sse| <= 3 % of 1.8 N*m
at 750 r/min.

--unseen SEED: instead of the file, a variant the code has not seen:
sim_host/machines/gen_nonideal.py with the stress fractions of the rated
torque (stiction 15 %, Coulomb 10 %, viscous 5 % at the rated speed, cogging
10 % peak, a passive load 20 %; each drawn in [F/2, F]), random slots and
cogging harmonics, and Rs, Ld, Lq, psi_pm, J each scaled within +-20 %.
"""
import argparse
import fcntl
import json
import math
import os
import re
import subprocess
import sys
import zlib


def set_key(text, section, key, value):
    """Set key = value in [section] (added if missing, section too)."""
    lines = text.splitlines()
    out, sec, done = [], None, False
    for i, ln in enumerate(lines):
        m = re.match(r"\s*\[(\w+)\]", ln)
        if m:
            if sec == section and not done:
                out.append("%s = %s" % (key, value))
                done = True
            sec = m.group(1)
        elif sec == section and re.match(r"\s*%s\s*=" % re.escape(key), ln):
            ln = "%s = %s" % (key, value)
            done = True
        out.append(ln)
    if not done:
        if sec != section:
            out.append("[%s]" % section)
        out.append("%s = %s" % (key, value))
    return "\n".join(out) + "\n"


def get_key(text, section, key):
    sec = None
    for ln in text.splitlines():
        m = re.match(r"\s*\[(\w+)\]", ln)
        if m:
            sec = m.group(1)
        elif sec == section:
            m = re.match(r"\s*%s\s*=\s*([^;\s]+)" % re.escape(key), ln)
            if m:
                return m.group(1)
    return None


def absolute_fluxmap(text, folder):
    f = get_key(text, "fluxmap", "file")
    if f is not None and not os.path.isabs(f):
        text = set_key(text, "fluxmap", "file", os.path.join(folder, f))
    return text


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print("$ " + " ".join(cmd))
    print(p.stdout, end="")
    return p.returncode


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", required=True, help="tools/sim")
    ap.add_argument("--machine", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--unseen", type=int, default=None, help="seed of an unseen variant")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    name = os.path.splitext(os.path.basename(a.machine))[0]
    if a.unseen is not None:
        gen = os.path.join(os.path.dirname(os.path.abspath(a.machine)), "gen_nonideal.py")
        name = "%s_unseen%d" % (name, a.unseen)
        out = os.path.join(a.work, name + ".ini")
        # A flux map fixes the inductances and the flux: its machine is not
        # scaled (the file's Ld, Lq, psi_pm would no longer describe it).
        fluxmap = get_key(open(a.machine).read(), "fluxmap", "file") is not None
        subprocess.run([sys.executable, gen, a.machine, out, "--stiction", "0.15", "--coulomb",
                        "0.10", "--viscous", "0.05", "--cogging", "0.10", "--passive", "0.20",
                        "--seed", str(a.unseen), "--spread", "0" if fluxmap else "0.2", "--name",
                        name], check=True)
        # the fluxmap (a saturated machine) stays where the base keeps it
        text = absolute_fluxmap(open(out).read(), os.path.dirname(os.path.abspath(a.machine)))
        open(out, "w").write(text)
        a.machine = out
    src = open(a.machine).read()
    if get_key(src, "filter", "type") is not None:
        # An output filter sits between the inverter and the motor: the drive
        # measures the two together (docs/identification.md, "Limits"), and
        # the plant takes a filter only with an ideal inverter. Reported as
        # skipped (ctest SKIP_RETURN_CODE), not as passed.
        print("%s: output filter [filter] between inverter and motor: identification of the "
              "motor behind it is not provided; skipped" % name)
        return 77
    folder = os.path.dirname(os.path.abspath(a.machine))
    h = zlib.crc32(name.encode())
    offset = 20.0 + (h % 3200) / 10.0  # 20 .. 340 deg: never the default 0
    theta0 = ((h >> 12) % 628) / 100.0  # rotor at rest anywhere

    plant = absolute_fluxmap(src, folder)
    plant = set_key(plant, "inverter", "dead_time_ns", "1000")
    # Device drop: 1.2 V (an IGBT's, a diode's) for the high-voltage machines;
    # a low-voltage drive switches MOSFETs of a few milliohm (tenths of a volt
    # at its currents): at most 2 % of the DC link (24 V: 0.48 V, 12 V: 0.24 V).
    vdc = float(get_key(src, "inverter", "vdc_v"))
    plant = set_key(plant, "inverter", "v_fwd_v", "%.4g" % min(1.2, 0.02 * vdc))
    plant = set_key(plant, "sensors", "encoder_offset_deg", "%.1f" % offset)
    plant = set_key(plant, "sensors", "encoder_direction", "-1")
    plant_ini = os.path.join(a.work, "plant.ini")
    open(plant_ini, "w").write(plant)

    ctrl = absolute_fluxmap(src, folder)
    for key, f in (("rs_ohm", 1.3), ("ld_mh", 0.7), ("lq_mh", 0.8), ("psi_pm_wb", 1.2)):
        ctrl = set_key(ctrl, "machine", key, "%.9g" % (float(get_key(src, "machine", key)) * f))
    ctrl = set_key(ctrl, "mechanics", "inertia_kgm2",
                   "%.9g" % (2.0 * float(get_key(src, "mechanics", "inertia_kgm2"))))
    ctrl_ini = os.path.join(a.work, "configured.ini")
    open(ctrl_ini, "w").write(ctrl)

    # tools/sim rebuilds the host-release simulator when it is stale: one at a
    # time (the per-machine tests run in parallel).
    with open(os.path.join(os.path.dirname(a.work), ".sim_build.lock"), "w") as lk:
        fcntl.flock(lk, fcntl.LOCK_EX)
        subprocess.run([a.sim, "--help"], stdout=subprocess.DEVNULL, check=True)
        fcntl.flock(lk, fcntl.LOCK_UN)
    # Then the binary it runs (tools/sim: $PMSM_SIM_BUILD_DIR or build/host-release).
    root = os.path.dirname(os.path.dirname(os.path.abspath(a.sim)))
    bdir = os.environ.get("PMSM_SIM_BUILD_DIR", os.path.join(root, "build", "host-release"))
    sim = os.path.join(bdir, "firmware", "sim")

    out_json = os.path.join(a.work, "identify.json")
    out_ini = os.path.join(a.work, "identified.ini")
    rc = run([sim, "--machine", plant_ini, "--control-machine", ctrl_ini, "--identify",
              "--theta0-elec", "%.2f" % theta0, "--metrics", out_json, "--identify-out", out_ini])
    fails = []
    if rc != 0:
        fails.append("identification exit status %d" % rc)
    r = json.load(open(out_json))
    idf, tru, err, oc = r["identified"], r["truth"], r["error"], r["identify"]

    def bound(label, value, lim):
        ok = value is not None and abs(value) <= lim
        print("  %-26s %10s  bound %g  %s" % (label, "n/a" if value is None else "%.4g" % value,
                                              lim, "ok" if ok else "FAIL"))
        if not ok:
            fails.append(label)

    print("%s: offset %.1f deg, direction -1, theta0 %.2f rad" % (name, offset, theta0))
    bound("rs error %", err["rs_pct"], 2.0)
    bound("ld error %", err["ld_pct"], 5.0)
    bound("lq error %", err["lq_pct"], 5.0)
    bound("psi_pm error %", err["psi_pm_pct"], 2.0)
    bound("encoder offset error deg", err["encoder_offset_deg"], 2.0)
    if idf["encoder_direction"] != tru["encoder_direction"]:
        fails.append("encoder direction %s, truth %s" % (idf["encoder_direction"],
                                                         tru["encoder_direction"]))
    cpr = 4 * tru["encoder_lines"]
    if idf["encoder_counts_measured"] is None or abs(idf["encoder_counts_measured"] - cpr) > 0.01 * cpr:
        fails.append("counts per revolution %s, truth %d" % (idf["encoder_counts_measured"], cpr))
    if idf["encoder_lines"] != tru["encoder_lines"]:
        fails.append("encoder lines %s, truth %s" % (idf["encoder_lines"], tru["encoder_lines"]))
    bound("inertia error %", err["inertia_pct"], 10.0)
    # Friction: relative where it is at least 1 % of the rated torque, else
    # what it makes (at the rated speed) below 1 % of it.
    t_r = float(get_key(src, "rated", "torque_nm"))
    w_r = float(get_key(src, "rated", "speed_rpm")) * math.pi / 30.0
    for label, key, scale in (("viscous friction", "friction_nms", w_r),
                              ("Coulomb friction", "coulomb_nm", 1.0)):
        got, want = idf[key], tru[key]
        if want * scale >= 0.01 * t_r:
            bound("%s error %%" % label, None if got is None else 100.0 * (got - want) / want, 15.0)
        else:
            bound("%s (truth %.3g) / rated torque %%" % (label, want),
                  None if got is None else 100.0 * (got - want) * scale / t_r, 1.0)
    bound("motor time s", oc["motor_time_s"], 10.0)
    bound("peak current / rated", oc["peak_current_a"] / oc["rated_current_a"], 1.0)

    if name == "thesis_spmsm":
        for c in ("m2ptfc", "drr"):
            mj = os.path.join(a.work, "tsse_%s.json" % c)
            rc = run([sim, "--machine", plant_ini, "--control-machine", out_ini, "--controller", c,
                      "--speed-rpm", "750", "--torque-ref", "1.8", "--duration", "0.5",
                      "--window", "0.2:0.5", "--metrics", mj])
            if rc != 0:
                fails.append("%s run exit status %d" % (c, rc))
                continue
            tsse = json.load(open(mj))["torque_sse_nm"]
            bound("%s T_sse / 1.8 N*m %%" % c, 100.0 * tsse / 1.8, 3.0)
    if fails:
        print("FAILED: " + "; ".join(fails))
        return 1
    print("passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
