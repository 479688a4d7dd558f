#!/usr/bin/env -S /usr/bin/python3
"""Torque-delivery sweep: does every controller give the torque asked of it, or
say why not?

For every machine file (default: every shipped sim_host/machines/*.ini, as
shipped), every controller (default m2ptfc, drr, fst, foc), speeds 0.1, 0.5,
0.9 and 1.3 x the rated speed (those above the machine's maximum speed are left
out), both halves - motoring (torque along the rotation) and regenerative
braking (against it) - and torque requests of 50 % and 90 % of the theoretical
envelope of that half at that speed (tools/envelope.py: rated current, 92 % of
Vdc/sqrt(3), Rs included), one dynamometer run of 0.3 s (metrics window
0.15:0.3 s) of ./tools/sim in torque mode from zero torque. A run

  meets      when |T_mean - T_request| <= max(5 % of |T_request|, 2 % of rated),
  is warned  when it misses but the simulator's warnings (or a fault) say so,
  is silent  when it misses without a word (the defect this sweep counts).

Requests inside the envelope must also pass unclipped: a warning that the
drive's torque or voltage limit clipped the request there is a defect of the
limit ("limit bites"), not an explanation. Two limits below the envelope are
physical and expected, each computed here from the machine file (not from what
the simulator prints):
  - the machine's rated torque ([rated] torque_nm; the thesis 80 kW IPMSM is
    rated 400 N*m, below the 698 N*m its rated current gives by MTPA);
  - for a controller that holds the file's fixed stator-flux reference
    (psi_ref_wb > 0: every DTC and MPC method; FOC forms its currents from the
    torque and holds none), the most torque the motor gives on that flux
    circle, T_max(psi_ref) ((3.9), (3.10), the MTPV point of the circle), times
    the drive's margin FLUX_MARGIN (braking FLUX_MARGIN_BRAKE): past the
    circle's peak dT/d(load angle) < 0 and a controller holding |psi_s| loses
    the load angle.
A request above the lower of the two is "limited": the drive must state that
limit (the JSON's torque_limit_nm, braking torque_limit_brake_nm, within
0.5 %) and warn naming its reason,
else the run is a defect ("limit-wrong"); the limit then takes the request's
place in meets / warned / silent (a miss against it needs a warning of its own).

usage: tools/torque_sweep.py [--machines A.ini,B.ini] [--controllers a,b]
                             [--speeds 0.1,0.5] [--fracs 0.5,0.9]
                             [--halves motoring,braking] [--json OUT.json] [--check]
                             [--jobs N | --scheduler tcp://HOST:PORT] [--store FILE]
--check: exit status 1 when a run is silent, bites, or the simulator fails.
The full sweep (8 machine files x 4 controllers x up to 4 speeds x 2 halves x
2 requests) takes a few minutes on two cores; CI runs a subset (tests/loop/CMakeLists.txt).
Runs through the study engine (tools/study_engine.py, docs/studies.md): results
stored in out/runs.sqlite (--store), a rerun computes only what is missing.
"""
import argparse
import configparser
import glob
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import envelope as env  # noqa: E402
import study_engine as se  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MDIR = os.path.join(ROOT, "sim_host", "machines")
CONTROLLERS = ("m2ptfc", "drr", "fst", "foc")
SPEEDS = (0.1, 0.5, 0.9, 1.3)
FRACS = (0.5, 0.9)
TOL_REL = 0.05  # of the request
TOL_RATED = 0.02  # of the rated torque
# Warnings of the simulator that are a drive limit acting on the request.
LIMIT_WORDS = ("was limited to", "outside the drive's torque limit",
               "outside the drive's braking torque limit")
# The drive's margin below T_max(psi_ref) (firmware/isr/speed_loop.h,
# FW_TORQUE_FLUX_MARGIN): the load angle's ripple must stay below the peak.
FLUX_MARGIN = 0.95
# The same in regenerative braking (control/regulators/field_weak_config.h,
# CTRL_FIELDWEAK_TORQUE_MARGIN_BRAKE_DEFAULT): there the zero vector carries the load
# angle toward the pull-out.
FLUX_MARGIN_BRAKE = 0.88
HALVES = ("motoring", "braking")
# Controllers that hold no fixed flux reference (they form the currents from
# the torque; the drive's limits are then MTPA's).
FLUX_FREE = ("foc",)


def flux_voltage_max(m, w, t):
    """Largest flux amplitude the voltage allows at electrical speed w and
    torque t (the drive's field weakening, control/regulators/field_weak.h):
    sqrt(V^2 - (Rs I)^2 - 2 Rs w T/(1.5 p)) / |w|, V = 92 % of Vdc/sqrt(3),
    I = |T| / (1.5 p psi_pm) at most the rated current; inf at standstill."""
    if w == 0.0:
        return float("inf")
    v = env.default_limits(m).v_max
    i = min(abs(t) / (1.5 * m.p * m.psi), m.i_rated)
    x = v * v - (m.rs * i) ** 2 - 2.0 * m.rs * w * t / (1.5 * m.p)
    return math.sqrt(max(x, 0.0)) / abs(w)


def stated_limit(mfile, ctrl, brake=False, rpm=0.0, tref=0.0):
    """(limit in N*m, reason words the warning must contain) of the physical
    limits below the envelope (module docstring), or (inf, None); brake: a
    regenerative-braking request. The flux circle is the file's reference, or
    where the voltage allows less at rpm and tref (field weakening) the
    voltage's ("voltage limit")."""
    m = env.load_machine(mfile)
    cp = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
    cp.read(mfile)
    psi_ref = cp.getfloat("rated", "psi_ref_wb", fallback=0.0)
    lim, why = m.torque_rated, "rated torque"
    if psi_ref > 0.0 and ctrl not in FLUX_FREE:
        psi_v = flux_voltage_max(m, env.rpm_to_we(m, rpm), tref)
        i_d, i_q = env.mtpv_flux_point(m, min(psi_ref, psi_v))
        t_flux = (FLUX_MARGIN_BRAKE if brake else FLUX_MARGIN) * env.torque(m, i_d, i_q)
        if t_flux < lim:
            lim, why = t_flux, "flux reference" if psi_ref <= psi_v else "voltage limit"
    return (lim, why) if math.isfinite(lim) and lim > 0 else (float("inf"), None)


def points(mfile, speeds, fracs, halves=HALVES):
    """(speed, fraction, request, rated torque) of each run; the speed is
    positive, a braking request negative."""
    m = env.load_machine(mfile)
    lim = env.default_limits(m)
    out = []
    for s in speeds:
        rpm = s * m.speed_rated_rpm
        if m.speed_max_rpm > 0 and rpm > m.speed_max_rpm * (1 + 1e-9):
            continue
        for half in halves:
            sign = -1 if half == "braking" else +1
            t_env = env.max_torque(m, lim, env.rpm_to_we(m, rpm), sign=sign).torque
            if t_env * sign <= 0:
                continue
            for f in fracs:
                out.append((rpm, f, f * t_env, m.torque_rated))
    return out


def run_of(build, job):
    """The simulator run of a job (study engine)."""
    mfile, ctrl, rpm, frac, tref, t_rated = job
    return se.Run(build, ["--machine", mfile, "--controller", ctrl, "--speed-rpm", f"{rpm:.6g}",
                          "--torque-ref", f"{tref:.6g}", "--duration", "0.3",
                          "--window", "0.15:0.3"],
                  tag=f"{os.path.basename(mfile)} {ctrl} {rpm:.1f} r/min {tref:.4g} N*m")


def judge(job, r):
    """The verdict of a job from its run's result (study_engine.Result)."""
    mfile, ctrl, rpm, frac, tref, t_rated = job
    res = {"machine": os.path.basename(mfile), "controller": ctrl, "rpm": rpm, "frac": frac,
           "request_nm": tref, "rated_nm": t_rated, "exit": r.rc,
           "half": "braking" if tref * rpm < 0.0 else "motoring"}
    brake = res["half"] == "braking"
    mj = r.metrics
    if mj is None or r.rc not in (0, 3):
        res.update(verdict="error", stderr=(r.stderr[-500:] if r.stored else r.reason))
        return res
    t = mj.get("torque_mean_nm")
    warns = mj.get("warnings", [])
    res.update(t_mean=t, warnings=warns, fault=mj.get("fault"))
    lim, why = stated_limit(mfile, ctrl, brake, rpm, tref)
    limited = abs(tref) > lim * (1 + 1e-9)
    # a limited request is met when the stated limit is delivered
    t_goal = math.copysign(lim, tref) if limited else tref
    tol = max(TOL_REL * abs(t_goal), TOL_RATED * t_rated)
    miss = t is None or abs(t - t_goal) > tol
    res["err_pct"] = None if t is None else 100.0 * (t - tref) / tref
    named = [w for w in warns if any(k in w for k in LIMIT_WORDS)]
    bites = bool(named) and not limited
    res["limited"] = why if limited else None
    if limited:
        # a drive that states no braking limit states its one limit for both;
        # in field weakening the limit is the period's (torque_max_nm)
        lim_json = mj.get("torque_limit_nm")
        if brake and mj.get("torque_limit_brake_nm") is not None:
            lim_json = mj["torque_limit_brake_nm"]
        if why == "voltage limit":
            lim_json = mj.get("torque_max_nm")
        res["expected_limit_nm"] = lim
        if not (lim_json is not None and abs(lim_json - lim) <= 0.005 * lim
                and any(why in w for w in named)):
            res.update(verdict="limit-wrong", limit_bites=False)
            return res
    # a limited run's miss against the limit needs a warning besides the clamp's
    explained = [w for w in warns if w not in named] if limited else warns
    if not miss and mj.get("fault") == "none":
        verdict = "limited" if limited else "meets"
    elif explained or mj.get("fault") != "none":
        verdict = "warned"
    else:
        verdict = "silent"
    res["verdict"] = verdict
    res["limit_bites"] = bites
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--machines", default="")
    ap.add_argument("--controllers", default=",".join(CONTROLLERS))
    ap.add_argument("--speeds", default=",".join(str(s) for s in SPEEDS))
    ap.add_argument("--fracs", default=",".join(str(f) for f in FRACS))
    ap.add_argument("--halves", default=",".join(HALVES))
    ap.add_argument("--json", default="")
    ap.add_argument("--check", action="store_true")
    se.add_arguments(ap)
    args = ap.parse_args()
    mfiles = ([os.path.join(MDIR, m) if os.sep not in m else m for m in args.machines.split(",")]
              if args.machines else sorted(glob.glob(os.path.join(MDIR, "*.ini"))))
    ctrls = [c for c in args.controllers.split(",") if c]
    speeds = [float(s) for s in args.speeds.split(",")]
    fracs = [float(f) for f in args.fracs.split(",")]
    halves = [h for h in args.halves.split(",") if h]
    bad = [h for h in halves if h not in HALVES]
    if bad:
        ap.error(f"--halves {','.join(bad)}: allowed {', '.join(HALVES)}")
    jobs = [(mf, c) + p for mf in mfiles for p in points(mf, speeds, fracs, halves)
            for c in ctrls]
    try:
        build = se.Build(os.environ["PMSM_SIM_EXE"]) if os.environ.get("PMSM_SIM_EXE") \
            else se.default_build()
        runs = [run_of(build, j) for j in jobs]
    except se.StudyInputError as e:
        print(f"torque sweep: error: {e}", file=sys.stderr)
        return 2
    with se.engine_or_exit(args, os.path.join(ROOT, "out"), "torque sweep") as eng:
        results = [judge(j, r) for j, r in zip(jobs, eng.run(runs))]
    counts = {}
    for h in halves:
        rs = [r for r in results if r["half"] == h]
        hc = {}
        for r in rs:
            hc[r["verdict"]] = hc.get(r["verdict"], 0) + 1
        print(f"  {h}: {len(rs)} runs: " + ", ".join(f"{k} {v}" for k, v in sorted(hc.items())))
    for r in results:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
        flag = r["verdict"] if r["verdict"] not in ("meets", "limited") else ""
        if r.get("limit_bites"):
            flag += " LIMIT-BITES"
        if flag:
            t = r.get("t_mean")
            print(f"{r['machine']:34s} {r['controller']:7s} {r['rpm']:8.1f} r/min "
                  f"{r['frac']:.0%} req {r['request_nm']:.4g} got "
                  f"{'n/a' if t is None else f'{t:.4g}'} N*m: {flag}"
                  + (f" [{r['warnings'][0][:160]}]" if r.get("warnings") else "")
                  + (f" fault {r['fault']}" if r.get("fault") not in (None, "none") else "")
                  + (f" {r.get('stderr', '')}" if r["verdict"] == "error" else ""))
    bites = sum(1 for r in results if r.get("limit_bites"))
    print(f"torque sweep: {len(results)} runs: " +
          ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + f"; limit bites {bites}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    if args.check and (counts.get("silent", 0) or counts.get("error", 0) or bites
                       or counts.get("limit-wrong", 0)):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
