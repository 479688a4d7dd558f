#!/usr/bin/env -S /usr/bin/python3
"""Torque-delivery sweep: does every controller give the torque asked of it, or
say why not?

For every machine file (default: every shipped sim_host/machines/*.ini, as
shipped), every controller (default m2ptfc, drr, fst, foc), speeds 0.1, 0.5,
0.9 and 1.3 x the rated speed (those above the machine's maximum speed are left
out) and torque requests of 50 % and 90 % of the theoretical envelope at that
speed (tools/envelope.py: rated current, 92 % of Vdc/sqrt(3), Rs included),
one dynamometer run of 0.3 s (metrics window 0.15:0.3 s) of ./tools/sim in
torque mode. A run

  meets      when |T_mean - T_request| <= max(5 % of |T_request|, 2 % of rated),
  is warned  when it misses but the simulator's warnings (or a fault) say so,
  is silent  when it misses without a word (the defect this sweep counts).

Requests inside the envelope must also pass unclipped: a warning that the
drive's torque or voltage limit clipped the request there is a defect of the
limit ("limit bites"), not an explanation.

usage: tools/torque_sweep.py [--machines A.ini,B.ini] [--controllers a,b]
                             [--speeds 0.1,0.5] [--fracs 0.5,0.9] [--jobs N]
                             [--json OUT.json] [--check]
--check: exit status 1 when a run is silent, bites, or the simulator fails.
The full sweep (8 machine files x 4 controllers x up to 4 speeds x 2 requests)
takes a few minutes on two cores; CI runs a subset (tests/loop/CMakeLists.txt).
"""
import argparse
import concurrent.futures as cf
import glob
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import envelope as env  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MDIR = os.path.join(ROOT, "sim_host", "machines")
CONTROLLERS = ("m2ptfc", "drr", "fst", "foc")
SPEEDS = (0.1, 0.5, 0.9, 1.3)
FRACS = (0.5, 0.9)
TOL_REL = 0.05  # of the request
TOL_RATED = 0.02  # of the rated torque
# Warnings of the simulator that are a drive limit acting on the request.
LIMIT_WORDS = ("was limited to", "outside the drive's torque limit")


def sim_cmd(args):
    exe = os.environ.get("PMSM_SIM_EXE")
    return [exe] if exe else [os.path.join(ROOT, "tools", "sim")]


def points(mfile, speeds, fracs):
    m = env.load_machine(mfile)
    lim = env.default_limits(m)
    out = []
    for s in speeds:
        rpm = s * m.speed_rated_rpm
        if m.speed_max_rpm > 0 and rpm > m.speed_max_rpm * (1 + 1e-9):
            continue
        t_env = env.max_torque(m, lim, env.rpm_to_we(m, rpm)).torque
        if t_env <= 0:
            continue
        for f in fracs:
            out.append((rpm, f, f * t_env, m.torque_rated))
    return out


def run_one(args, job):
    mfile, ctrl, rpm, frac, tref, t_rated = job
    fd, path = tempfile.mkstemp(suffix=".json")
    os.close(fd)
    cmd = sim_cmd(args) + ["--machine", mfile, "--controller", ctrl, "--speed-rpm",
                           f"{rpm:.6g}", "--torque-ref", f"{tref:.6g}", "--duration", "0.3",
                           "--window", "0.15:0.3", "--metrics", path]
    r = subprocess.run(cmd, capture_output=True, text=True)
    res = {"machine": os.path.basename(mfile), "controller": ctrl, "rpm": rpm, "frac": frac,
           "request_nm": tref, "rated_nm": t_rated, "exit": r.returncode}
    try:
        with open(path) as f:
            mj = json.load(f)
    except (OSError, ValueError):
        mj = None
    os.unlink(path)
    if mj is None or r.returncode not in (0, 3):
        res.update(verdict="error", stderr=r.stderr[-500:])
        return res
    t = mj.get("torque_mean_nm")
    warns = mj.get("warnings", [])
    res.update(t_mean=t, warnings=warns, fault=mj.get("fault"))
    tol = max(TOL_REL * abs(tref), TOL_RATED * t_rated)
    miss = t is None or abs(t - tref) > tol
    res["err_pct"] = None if t is None else 100.0 * (t - tref) / tref
    bites = any(w for w in warns if any(k in w for k in LIMIT_WORDS))
    if not miss and mj.get("fault") == "none":
        verdict = "meets"
    elif warns or mj.get("fault") != "none":
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
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", default="")
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    mfiles = ([os.path.join(MDIR, m) if os.sep not in m else m for m in args.machines.split(",")]
              if args.machines else sorted(glob.glob(os.path.join(MDIR, "*.ini"))))
    ctrls = [c for c in args.controllers.split(",") if c]
    speeds = [float(s) for s in args.speeds.split(",")]
    fracs = [float(f) for f in args.fracs.split(",")]
    jobs = [(mf, c) + p for mf in mfiles for p in points(mf, speeds, fracs) for c in ctrls]
    with cf.ThreadPoolExecutor(max_workers=max(args.jobs, 1)) as ex:
        results = list(ex.map(lambda j: run_one(args, j), jobs))
    counts = {}
    for r in results:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
        flag = r["verdict"] if r["verdict"] != "meets" else ""
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
    if args.check and (counts.get("silent", 0) or counts.get("error", 0) or bites):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
