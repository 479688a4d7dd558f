#!/usr/bin/env -S /usr/bin/python3
"""Controller comparison on the thesis SPMSM (REFERENCE.md sections 5-6).

For every controller of `sim --list-controllers` (so controllers added later appear
automatically):
  * steady state at 750 and 2250 r/min (dynamometer), torque reference 1.8 N*m (the
    thesis' 1.8 N*m load held by its speed loop: in steady state the speed PI outputs
    the load torque, so the dynamometer with T_ref = 1.8 N*m is the same operating
    point without the PI transient), each controller at its default fs, M3 at the
    fs of thesis Table 6.2 (12 kHz at 750, 16 kHz at 2250 r/min) and the per-speed
    tunables of SET_OVERRIDE (Table 6.2 where they keep torque control);
    simulated DURATION s (default 0.3) of which the first SETTLE s (0.1) are not
    measured;
  * the dynamic test of thesis Fig. 4.14: free mechanics, load 1.6 N*m (passive: it
    changes sign with the speed), T_ref 0 -> 2 N*m at 2 ms, -2 N*m once the speed
    reaches 1500 r/min; rise time (0 -> 90 % of 2 N*m), fall time (2 -> -1.8 N*m) and
    whether the reversal is stable (speed through zero below -100 r/min and negative at
    the end, torque over the last 10 ms within 0.2 T_rated of -2 N*m, no fault).
Indices: from the plant's true signals on a Ts/10 grid (plant sampling); the ripple
from the control instants is in the JSON files (*_ctrl keys).
Runs in parallel processes (--jobs, default 2); deterministic for a given --seed.
Writes OUT/report.md with tables and PNG plots.
"""
import argparse
import concurrent.futures as cf
import json
import os
import shutil
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MACHINE = os.path.join(ROOT, "sim_host", "machines", "thesis_spmsm.ini")
SPEEDS = (750, 2250)
LOAD_NM = 1.8
# Per-controller sampling-frequency overrides (thesis Table 6.2).
FS_OVERRIDE = {("m3", 750): 12000, ("m3", 2250): 16000, ("m2ptfc", 2250): 11000}
# Per-speed controller tunables of thesis Table 6.2 where they keep torque control
# (owner mpc2): M3's zeta = 110 N*m/Wb at 2250 r/min. Table 6.2's M1 250 / 640 and
# M3 440 N*m/Wb exceed the limit sqrt(3)*1.5*p*psi_pm/Ls = 149.5 N*m/Wb of
# control/ctrl_m1.h (they trip over-current); those runs keep the controllers'
# default zeta = T_rated/psi_pm (equal importance). M2's eps_psi: 6.60 mWb is its
# default, 9.42 mWb at 2250 r/min.
SET_OVERRIDE = {("m3", 2250): ["zeta=110"], ("m2", 2250): ["eps_psi=0.00942"]}
T_RATED = 2.4
# The load is passive (like friction or a loading machine): it acts against the
# rotation once the rotor turns, so it starts with the torque step and changes sign
# with the speed.
DYN_SCENARIO = """# thesis Fig. 4.14: 0 -> 2 N*m, then -2 N*m at 1500 r/min; passive 1.6 N*m load
at 0 torque_ref=0 load=0
at 0.002 torque_ref=2 load=1.6
when speed>=1500 torque_ref=-2
when speed<=0 load=-1.6
"""
DYN_DURATION = 0.12


def sim_binary():
    """Build the simulator once through tools/sim, return the binary path."""
    r = subprocess.run([os.path.join(ROOT, "tools", "sim"), "--list-controllers"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"compare: tools/sim failed:\n{r.stderr}")
    bdir = os.environ.get("PMSM_SIM_BUILD_DIR", os.path.join(ROOT, "build", "host-release"))
    ctrls = []
    for line in r.stdout.splitlines():
        parts = line.split("\t")
        if len(parts) >= 3:
            ctrls.append((parts[0], int(parts[1]), parts[2]))
    return os.path.join(bdir, "firmware", "sim"), ctrls


def run(cmd):
    t0 = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr, time.time() - t0


def load_trace(path):
    return np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))


def dynamic_indices(d):
    t, tq, tref, spd = d["t"], d["torque"], d["torque_ref"], d["speed_rpm"]
    res = {"rise_ms": None, "fall_ms": None, "reached_1500": False, "stable": False,
           "end_rpm": float(spd[-1]), "back_mean_nm": None, "min_rpm": float("nan")}
    up = np.nonzero((t > 0.002) & (tq >= 0.9 * 2.0))[0]
    if up.size:
        res["rise_ms"] = (t[up[0]] - 0.002) * 1e3
    rev = np.nonzero(tref <= -1.99)[0]
    if rev.size:
        res["reached_1500"] = True
        t_rev = t[rev[0]]
        dn = np.nonzero((t >= t_rev) & (tq <= -0.9 * 2.0))[0]
        if dn.size:
            res["fall_ms"] = (t[dn[0]] - t_rev) * 1e3
    last = t >= t[-1] - 0.010
    res["back_mean_nm"] = float(np.mean(tq[last]))
    res["min_rpm"] = float(np.min(spd[rev[0]:])) if rev.size else float("nan")
    # Stable reversal: the speed went through zero into backward motoring and the
    # torque still tracks -2 N*m (within the 0.2 T_rated steady-state error of
    # hysteresis DTC, thesis Fig. 5.3) over the last 10 ms.
    res["stable"] = bool(res["reached_1500"] and res["min_rpm"] < -100.0 and spd[-1] < 0.0 and
                         abs(res["back_mean_nm"] + 2.0) <= 0.2 * T_RATED)
    return res


def fmt(x, f="{:.4f}"):
    return "n/a" if x is None or (isinstance(x, float) and not np.isfinite(x)) else f.format(x)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "out"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--settle", type=float, default=0.1)
    ap.add_argument("--controllers", default="", help="comma-separated subset")
    a = ap.parse_args()
    if not (0.0 <= a.settle < a.duration <= 10.0):
        sys.exit("compare: need 0 <= --settle < --duration <= 10")
    if a.jobs < 1:
        sys.exit("compare: --jobs must be >= 1")

    sim, ctrls = sim_binary()
    if a.controllers:
        want = a.controllers.split(",")
        unknown = [w for w in want if w not in [c[0] for c in ctrls]]
        if unknown:
            sys.exit(f"compare: unknown controller(s): {', '.join(unknown)}")
        ctrls = [c for c in ctrls if c[0] in want]
    os.makedirs(a.out, exist_ok=True)
    runs_dir = os.path.join(a.out, "runs")
    shutil.rmtree(runs_dir, ignore_errors=True)
    os.makedirs(runs_dir)
    scn = os.path.join(runs_dir, "dynamic.scn")
    with open(scn, "w") as f:
        f.write(DYN_SCENARIO)

    jobs = []
    for name, fs_def, _ in ctrls:
        for rpm in SPEEDS:
            fs = FS_OVERRIDE.get((name, rpm), fs_def)
            base = os.path.join(runs_dir, f"{name}_{rpm}")
            cmd = [sim, "--machine", MACHINE, "--controller", name, "--fs", str(fs),
                   "--speed-rpm", str(rpm), "--torque-ref", str(LOAD_NM),
                   "--duration", str(a.duration), "--window", f"{a.settle}:{a.duration}",
                   "--seed", str(a.seed), "--metrics", base + ".json", "--trace", base + ".csv",
                   "--trace-window", f"{a.duration - 0.005}:{a.duration}"]
            for kv in SET_OVERRIDE.get((name, rpm), []):
                cmd += ["--set", kv]
            jobs.append(("steady", name, rpm, fs, base, cmd))
        base = os.path.join(runs_dir, f"{name}_dynamic")
        cmd = [sim, "--machine", MACHINE, "--controller", name, "--free", "--scenario", scn,
               "--duration", str(DYN_DURATION), "--window", f"{DYN_DURATION - 0.01}:{DYN_DURATION}",
               "--seed", str(a.seed), "--metrics", base + ".json", "--trace", base + ".csv",
               "--trace-decimation", "2"]
        jobs.append(("dynamic", name, 0, fs_def, base, cmd))

    t_start = time.time()
    results = {}
    failed = []
    print(f"compare: {len(jobs)} simulations ({len(ctrls)} controllers), {a.jobs} processes")
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = {ex.submit(run, j[5]): j for j in jobs}
        for k, fut in enumerate(cf.as_completed(futs), 1):
            kind, name, rpm, fs, base, _ = futs[fut]
            rc, out, err, dt = fut.result()
            label = f"{name} {'dynamic' if kind == 'dynamic' else str(rpm) + ' r/min'}"
            print(f"  [{k:2d}/{len(jobs)}] {label:<22s} {dt:5.1f} s  "
                  f"{ {0: 'ok', 3: 'tripped'}.get(rc, 'FAILED')}", flush=True)
            # Exit status 3: the drive tripped; the metrics (up to the trip) are written.
            if rc not in (0, 3) or not os.path.exists(base + ".json"):
                failed.append((label, err.strip()))
                continue
            with open(base + ".json") as f:
                results[(kind, name, rpm)] = json.load(f)
            results[(kind, name, rpm)]["fs_used"] = fs
    wall = time.time() - t_start

    # ---- steady-state table ----
    hdr = (f"{'controller':<10s} {'r/min':>5s} {'fs kHz':>6s} {'T_rip':>7s} {'psi_rip':>8s} "
           f"{'T_sse':>7s} {'f_av Hz':>7s} {'THD_I %':>7s} {'T_mean':>7s} {'fault':>8s}")
    lines = [hdr, "-" * len(hdr)]
    md = ["| controller | r/min | fs (kHz) | T_rip (N·m) | ψ_rip (mWb) | T_sse (N·m) | "
          "f_av (Hz) | THD_I (%) | mean T (N·m) | T_rip ctrl-instants (N·m) | fault |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, _, _ in ctrls:
        for rpm in SPEEDS:
            m = results.get(("steady", name, rpm))
            if m is None:
                lines.append(f"{name:<10s} {rpm:>5d}  (run failed)")
                md.append(f"| {name} | {rpm} | | run failed | | | | | | | |")
                continue
            psi_mwb = None if m["flux_ripple_wb"] is None else 1e3 * m["flux_ripple_wb"]
            lines.append(f"{name:<10s} {rpm:>5d} {m['fs_hz'] / 1e3:>6.1f} "
                         f"{fmt(m['torque_ripple_nm']):>7s} {fmt(m['flux_ripple_wb'], '{:.5f}'):>8s} "
                         f"{fmt(m['torque_sse_nm']):>7s} {fmt(m['f_av_hz'], '{:.0f}'):>7s} "
                         f"{fmt(m['thd_i_pct'], '{:.2f}'):>7s} {fmt(m['torque_mean_nm']):>7s} "
                         f"{m['fault']:>8s}")
            md.append(f"| {name} | {rpm} | {m['fs_hz'] / 1e3:.1f} | {fmt(m['torque_ripple_nm'])} | "
                      f"{fmt(psi_mwb, '{:.3f}')} | {fmt(m['torque_sse_nm'])} | "
                      f"{fmt(m['f_av_hz'], '{:.0f}')} | {fmt(m['thd_i_pct'], '{:.2f}')} | "
                      f"{fmt(m['torque_mean_nm'])} | {fmt(m['torque_ripple_ctrl_nm'])} | "
                      f"{m['fault']} |")
    print()
    print("\n".join(lines))

    # ---- dynamic test ----
    dyn_rows = ["| controller | rise (ms) | fall (ms) | reached 1500 r/min | speed at end (r/min) | "
                "mean T last 10 ms (N·m) | reversal stable | fault |", "|---|---|---|---|---|---|---|---|"]
    print(f"\n{'controller':<10s} {'rise ms':>8s} {'fall ms':>8s} {'end r/min':>9s} "
          f"{'T last 10ms':>11s} {'stable':>7s}")
    dyn = {}
    for name, _, _ in ctrls:
        m = results.get(("dynamic", name, 0))
        base = os.path.join(runs_dir, f"{name}_dynamic")
        if m is None or not os.path.exists(base + ".csv"):
            dyn_rows.append(f"| {name} | run failed | | | | | | |")
            continue
        d = load_trace(base + ".csv")
        r = dynamic_indices(d)
        r["fault"] = m["fault"]
        if m["fault"] != "none":
            r["stable"] = False
        dyn[name] = (d, r)
        print(f"{name:<10s} {fmt(r['rise_ms'], '{:.3f}'):>8s} {fmt(r['fall_ms'], '{:.3f}'):>8s} "
              f"{r['end_rpm']:>9.0f} {r['back_mean_nm']:>11.3f} {'yes' if r['stable'] else 'NO':>7s}")
        dyn_rows.append(f"| {name} | {fmt(r['rise_ms'], '{:.3f}')} | {fmt(r['fall_ms'], '{:.3f}')} | "
                        f"{'yes' if r['reached_1500'] else 'no'} | {r['end_rpm']:.0f} | "
                        f"{fmt(r['back_mean_nm'], '{:.3f}')} | {'yes' if r['stable'] else '**no**'} | "
                        f"{r['fault']} |")

    # ---- plots ----
    figs = []
    names = [c[0] for c in ctrls]
    for rpm in SPEEDS:
        fig, ax = plt.subplots(2, 2, figsize=(11, 6.5))
        keys = [("torque_ripple_nm", "T_rip (N·m)", 1), ("flux_ripple_wb", "ψ_rip (mWb)", 1e3),
                ("f_av_hz", "f_av (Hz)", 1), ("thd_i_pct", "THD_I (%)", 1)]
        for axx, (k, lab, sc) in zip(ax.flat, keys):
            ms = [results.get(("steady", n, rpm)) or {} for n in names]
            # A run that tripped has no steady state: no bar, marked "trip".
            vals = [np.nan if (m.get(k) is None or m.get("fault", "none") != "none")
                    else m[k] * sc for m in ms]
            axx.bar(range(len(names)), vals, color="tab:blue")
            for i, m in enumerate(ms):
                if m.get("fault", "none") != "none" or not m:
                    axx.text(i, 0, "trip" if m else "fail", rotation=90, ha="center",
                             va="bottom", fontsize=7, color="tab:red")
            axx.set_xticks(range(len(names)))
            axx.set_xticklabels(names, rotation=60, fontsize=8)
            axx.set_title(lab, fontsize=10)
            axx.grid(True, axis="y", lw=0.3)
        fig.suptitle(f"Steady-state indices, SPMSM {rpm} r/min, T = {LOAD_NM} N·m")
        fig.tight_layout()
        fn = f"indices_{rpm}.png"
        fig.savefig(os.path.join(a.out, fn), dpi=100)
        plt.close(fig)
        figs.append((f"Indices at {rpm} r/min", fn))
    wave_figs = []
    for name in names:
        fig, ax = plt.subplots(4, 2, figsize=(12, 8), sharex="col")
        for col, rpm in enumerate(SPEEDS):
            p = os.path.join(runs_dir, f"{name}_{rpm}.csv")
            if not os.path.exists(p) or results.get(("steady", name, rpm)) is None:
                continue
            d = load_trace(p)
            tm = (d["t"] - d["t"][0]) * 1e3
            ax[0, col].plot(tm, d["torque"], lw=0.6)
            ax[0, col].plot(tm, d["torque_ref"], lw=0.8, ls="--", color="k")
            ax[1, col].plot(tm, d["psi_s"], lw=0.6, color="tab:green")
            ax[2, col].plot(tm, d["i_a"], lw=0.6, color="tab:red")
            ax[3, col].step(tm, d["vec"], where="post", lw=0.5, color="tab:purple")
            axd = ax[3, col].twinx()
            axd.step(tm, d["duty"], where="post", lw=0.5, color="tab:orange")
            axd.set_ylim(-0.05, 1.05)
            ax[0, col].set_title(f"{rpm} r/min, fs {results[('steady', name, rpm)]['fs_hz'] / 1e3:.0f} kHz")
            ax[3, col].set_xlabel("time (ms), last 5 ms")
        for r_, lab in enumerate(("T (N·m)", "|ψs| (Wb)", "i_a (A)", "vector / duty")):
            ax[r_, 0].set_ylabel(lab)
        for x in ax.flat:
            x.grid(True, lw=0.3)
        fig.suptitle(f"{name}: steady state (thesis Figs. 6.15-6.16 layout)")
        fig.tight_layout()
        fn = f"wave_{name}.png"
        fig.savefig(os.path.join(a.out, fn), dpi=90)
        plt.close(fig)
        wave_figs.append((name, fn))
    if dyn:
        n = len(dyn)
        fig, ax = plt.subplots(n, 2, figsize=(12, 1.9 * n + 0.8), squeeze=False)
        for i, (name, (d, r)) in enumerate(dyn.items()):
            tm = d["t"] * 1e3
            ax[i, 0].plot(tm, d["torque"], lw=0.5)
            ax[i, 0].plot(tm, d["torque_ref"], lw=0.8, ls="--", color="k")
            ax[i, 0].set_ylabel(name)
            ax[i, 1].plot(tm, d["speed_rpm"], lw=0.8, color="tab:brown")
            for x in ax[i]:
                x.grid(True, lw=0.3)
        ax[0, 0].set_title("torque (N·m)")
        ax[0, 1].set_title("speed (r/min)")
        ax[-1, 0].set_xlabel("time (ms)")
        ax[-1, 1].set_xlabel("time (ms)")
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "dynamic.png"), dpi=90)
        plt.close(fig)

    with open(os.path.join(a.out, "report.md"), "w") as f:
        f.write("# Controller comparison, thesis SPMSM\n\n")
        f.write(f"Generated by `tools/compare.py` (seed {a.seed}). Steady state: dynamometer, "
                f"T_ref = {LOAD_NM} N·m, {a.duration} s simulated, indices over "
                f"[{a.settle}, {a.duration}] s from the plant's true signals on a Ts/10 grid "
                "(REFERENCE.md §5; T_rip = std of torque, ψ_rip = std of |ψs|, T_sse = mean(T_ref − T), "
                "f_av = mean per-leg switching frequency, THD_I of phase a up to 10 kHz). The last "
                "column is the torque ripple sampled at the control instants only. Each controller at "
                "its default fs; M3 at 12/16 kHz and M2PTFC at 11 kHz at 2250 r/min (thesis "
                "Table 6.2). Tunables set per speed (Table 6.2 where it keeps torque control): "
                f"{', '.join(f'{n} {r} r/min {chr(32).join(v)}' for (n, r), v in SET_OVERRIDE.items())}; "
                "M1/M3/FS-MPTFC weights otherwise T_rated/psi_pm (control/ctrl_m1.h).\n\n")
        f.write("## Steady state\n\n" + "\n".join(md) + "\n\n")
        for title, fn in figs:
            f.write(f"![{title}]({fn})\n\n")
        f.write("## Dynamic test (thesis Fig. 4.14)\n\nFree mechanics, passive load 1.6 N·m "
                "(applied with the torque step, changes sign with the speed), T_ref 0 → 2 N·m at 2 ms, → −2 N·m at 1500 r/min, "
                f"{DYN_DURATION} s. Rise: 0 → 1.8 N·m after the step; fall: 2 → −1.8 N·m after "
                "the reversal command (trace every Ts/5). Stable: the speed went below −100 r/min and "
                "is negative at the end, and the mean torque of the last 10 ms is within 0.48 N·m "
                "(0.2 T_rated, thesis Fig. 5.3) of −2 N·m, no fault. "
                "Thesis: rise ≈ 0.2 ms, fall ≈ 0.27 ms; ZST unstable at the reversal.\n\n")
        f.write("\n".join(dyn_rows) + "\n\n![dynamic](dynamic.png)\n\n")
        f.write("## Steady-state waveforms (last 5 ms)\n\n")
        for name, fn in wave_figs:
            f.write(f"### {name}\n\n![{name}]({fn})\n\n")
        if failed:
            f.write("## Failed runs\n\n")
            for label, err in failed:
                f.write(f"- {label}: `{err}`\n")
    print(f"\ncompare: {len(jobs)} simulations in {wall:.1f} s wall; report: "
          f"{os.path.relpath(os.path.join(a.out, 'report.md'), os.getcwd())}")
    if failed:
        for label, err in failed:
            print(f"compare: FAILED {label}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
