"""The comparison report's decision table: per controller what it is best and worst at,
its indices and its cost, and "use X for Y" sentences derived from those numbers.

tools/compare.py adds the runs of jobs() to its own (the robustness and sensorless runs
of every controller), then calls section() with its results; the cost columns come
from out/bench.json (./tools/bench, which ./tools/demo runs or reuses) and the tunables
from the simulator's --list-tunables. Every cell, rank and sentence below is computed
here from those numbers; nothing in the table is written by hand.

Columns (lower is better in every one):
  ripple      torque ripple T_rip (standard deviation, N*m) at an average switching
              frequency of FAV_HZ, interpolated on each controller's fs sweep (log-log),
              geometric mean of the speeds where the sweep reached it
  thd         phase-current THD_I (%), the same way
  rise        the dynamic test's torque step 0 -> 2 N*m: time to 90 % (ms)
  sse         |mean torque error| at the default fs, % of T_ref, mean of the speeds
  robust      the largest shift of the mean torque (% of T_ref) from the controller's own
              nominal run when it is configured with one machine parameter 20 % off (Rs,
              Ld and Lq, psi_pm; each -20 % and +20 %), 750 r/min; a trip is the worst
  sensorless  without the encoder, from standstill (forced start, handover to the flux
              observer) to 300 and 800 r/min and a 1.8 N*m load step: the observer's
              angle error, rms over the run (deg); a trip is the worst
  cpu_mean, cpu_max   Cortex-M4 instructions of the PWM interrupt (fw_isr_fast), mean and
              worst over the running periods (./tools/bench, QEMU, exact)
  flash       bytes the controller adds to a Cortex-M4 image (./tools/bench)
  tunables    the controller's tunables (--list-tunables)
"""
import math
import os
import subprocess

import fieldweak_studies as fws

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SPMSM = os.path.join(ROOT, "sim_host", "machines", "thesis_spmsm.ini")
FAV_HZ = 4000.0
T_REF = 1.8
ROBUST_RPM = 750
ROBUST_CASES = (("Rs −20 %", {("machine", "rs_ohm"): 0.8}),
                ("Rs +20 %", {("machine", "rs_ohm"): 1.2}),
                ("L −20 %", {("machine", "ld_mh"): 0.8, ("machine", "lq_mh"): 0.8}),
                ("L +20 %", {("machine", "ld_mh"): 1.2, ("machine", "lq_mh"): 1.2}),
                ("ψpm −20 %", {("machine", "psi_pm_wb"): 0.8}),
                ("ψpm +20 %", {("machine", "psi_pm_wb"): 1.2}))
# Sensorless profile (free rotor, speed mode): the ctest sensorless_loop's start, shorter.
SL_SCENARIO = ("at 0 speed_ref=0 load=0.5\nat 0.3 speed_ref=300\nat 0.6 speed_ref=800\n"
               "at 0.8 load=1.8\n")
SL_DURATION = 1.0
SL_SCENARIO_FAST = "at 0 speed_ref=0 load=0.5\nat 0.1 speed_ref=300\n"
SL_DURATION_FAST = 0.3
# Within this share of the best, a controller ties with it in a sentence.
TIE = 0.05
# A controller whose mean torque misses the reference by more than this (% of T_ref,
# the report's threshold for a steady-state error) is recommended for nothing: a
# small ripple or interrupt is worth little on the wrong torque.
USABLE_SSE = 5.0

# key, column head, format, purpose ("use X for ..."), in the best/worst columns
COLUMNS = (
    ("ripple", f"T_rip at {FAV_HZ / 1e3:g} kHz (N·m)", "{:.3f}",
     "the lowest torque ripple at equal switching frequency", True),
    ("thd", f"THD_I at {FAV_HZ / 1e3:g} kHz (%)", "{:.1f}",
     "the cleanest phase current at equal switching frequency", True),
    ("rise", "step 0→2 N·m (ms)", "{:.2f}", "the fastest torque step", True),
    ("sse", "\\|T_sse\\| (%)", "{:.1f}", "the most accurate mean torque", True),
    ("robust", "±20 % params: torque shift (%)", "{:.1f}",
     "holding the torque when the machine's parameters are 20 % off", True),
    ("sensorless", "sensorless: angle error (° rms)", "{:.2f}",
     "running without an encoder", True),
    ("cpu_mean", "M4 instr. mean", "{:.0f}", "the smallest processor load per period", True),
    ("cpu_max", "M4 instr. worst", "{:.0f}", "the smallest worst-case interrupt", False),
    ("flash", "flash (B)", "{:.0f}", "the least flash", True),
    ("tunables", "tunables", "{:.0f}", "the fewest settings to tune", True),
)
NAMES = {c[0]: c for c in COLUMNS}
UNITS = {"ripple": " N·m", "thd": " %", "rise": " ms", "sse": " % of T_ref",
         "robust": " % of T_ref", "sensorless": "° rms", "cpu_mean": " instructions",
         "cpu_max": " instructions", "flash": " B", "tunables": ""}
QUALITY = ("ripple", "thd", "rise", "sse", "robust", "sensorless")
COST = ("cpu_mean", "flash", "tunables")
SHORT = {"ripple": "torque ripple", "thd": "current THD", "rise": "torque step",
         "sse": "mean-torque accuracy", "robust": "parameter errors",
         "sensorless": "sensorless running", "cpu_mean": "processor load",
         "cpu_max": "worst-case interrupt", "flash": "flash", "tunables": "tuning effort"}


def jobs(name, sim, runs_dir, common, fast=False):
    """(key, metrics base, command) of the decision table's own runs for one controller:
    the robustness cases at ROBUST_RPM and the sensorless run."""
    out = []
    dur, settle = (0.06, 0.03) if fast else (0.3, 0.1)
    for i, (case, scale) in enumerate(ROBUST_CASES):
        ini = os.path.join(runs_dir, f"decide_robust_{i}.ini")
        if not os.path.exists(ini):
            fws.write_ini(SPMSM, ini, {k: fws.ini_value(SPMSM, *k) * v for k, v in scale.items()})
        base = os.path.join(runs_dir, f"decide_{name}_robust_{i}")
        out.append((("robust", name, case), base,
                    [sim, "--machine", SPMSM, "--control-machine", ini, "--controller", name,
                     "--speed-rpm", str(ROBUST_RPM), "--torque-ref", str(T_REF),
                     "--duration", str(dur), "--window", f"{settle}:{dur}",
                     "--metrics", base + ".json"] + common))
    scn = os.path.join(runs_dir, "decide_sensorless.scn")
    if not os.path.exists(scn):
        with open(scn, "w") as f:
            f.write(SL_SCENARIO_FAST if fast else SL_SCENARIO)
    dur = SL_DURATION_FAST if fast else SL_DURATION
    base = os.path.join(runs_dir, f"decide_{name}_sensorless")
    out.append((("sensorless", name), base,
                [sim, "--machine", SPMSM, "--controller", name, "--free", "--sensorless",
                 "--speed-ref-rpm", "0", "--scenario", scn, "--duration", str(dur),
                 "--window", f"0:{dur}", "--metrics", base + ".json"] + common))
    return out


def tunables(sim, name):
    """The number of a controller's tunables (--list-tunables), None if it cannot tell."""
    r = subprocess.run([sim, "--list-tunables", name, "--machine", SPMSM], capture_output=True,
                       text=True)
    if r.returncode != 0:
        return None
    rows = [ln for ln in r.stdout.splitlines() if ln.strip() and not ln.startswith("#")]
    return len(rows) - 1  # the header row


def geomean(xs):
    xs = [x for x in xs if x is not None and x > 0]
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else None


def values(names, results, speeds, fav, dyn, bench, n_tunables):
    """{name: {key: value or None}} and {name: {key: why it is None or a note}}.
    fav(name, rpm, key): the sweep's value at FAV_HZ or None."""
    val, note = {}, {}
    for n in names:
        v, w = {}, {}
        rip = [fav(n, r, "torque_ripple_nm") for r in speeds]
        v["ripple"] = geomean(rip)
        v["thd"] = geomean([fav(n, r, "thd_i_pct") for r in speeds])
        if v["ripple"] is None:
            w["ripple"] = f"its sweep does not reach {FAV_HZ / 1e3:g} kHz without a trip"
        elif None in rip:
            w["ripple"] = ("T_rip and THD_I at " + " and ".join(
                f"{r}" for r, x in zip(speeds, rip) if x is not None) + " r/min only (the sweep "
                f"at {' and '.join(str(r) for r, x in zip(speeds, rip) if x is None)} r/min does "
                f"not reach {FAV_HZ / 1e3:g} kHz without a trip)")
        d = dyn.get(n)
        v["rise"] = d[1]["rise_ms"] if d else None
        sse = []
        for r in speeds:
            m = results.get(("steady", n, r), {}).get("m")
            if m is not None and m.get("fault") == "none" and m.get("torque_sse_nm") is not None:
                sse.append(100.0 * abs(m["torque_sse_nm"]) / T_REF)
        v["sse"] = sum(sse) / len(sse) if sse else None
        if len(sse) < len(speeds):
            w["sse"] = "a speed tripped"
        worst, worst_case, trips = None, None, []
        nom = results.get(("steady", n, ROBUST_RPM), {}).get("m") or {}
        t_nom = nom.get("torque_mean_nm") if nom.get("fault") == "none" else None
        for case, _ in ROBUST_CASES:
            m = results.get(("robust", n, case), {}).get("m")
            if m is None or m.get("fault") != "none" or m.get("torque_mean_nm") is None:
                trips.append(case)
                continue
            if t_nom is None:
                continue
            e = 100.0 * abs(m["torque_mean_nm"] - t_nom) / T_REF
            if worst is None or e > worst:
                worst, worst_case = e, case
        v["robust"] = math.inf if trips else worst
        w["robust"] = ("trips at " + ", ".join(trips)) if trips else (
            worst_case or f"no nominal run at {ROBUST_RPM} r/min")
        m = results.get(("sensorless", n), {}).get("m")
        if m is None or m.get("fault") != "none":
            v["sensorless"] = math.inf
            w["sensorless"] = "trips" if m is not None else "no run"
        else:
            v["sensorless"] = m.get("est_angle_err_rms_deg")
        b = (bench or {}).get(n) or {}
        v["cpu_mean"] = b.get("cm4_instr_mean")
        v["cpu_max"] = b.get("cm4_instr_max")
        v["flash"] = b.get("flash_bytes")
        for k in ("cpu_mean", "cpu_max", "flash"):
            if v[k] is None:
                w[k] = "not measured: ./tools/bench writes out/bench.json"
        v["tunables"] = n_tunables.get(n)
        val[n], note[n] = v, w
    return val, note


def ranks(val, key):
    """{name: rank (1 = best)} among the controllers with a finite or infinite value;
    equal values share a rank."""
    xs = [(v[key], n) for n, v in val.items() if v.get(key) is not None]
    return {n: 1 + sum(1 for y, _ in xs if y < x) for x, n in xs}


def cell(v, key):
    x = v.get(key)
    if x is None:
        return "n/a"
    if x == math.inf:
        return "trips"
    return NAMES[key][2].format(x)


def best_worst(val, names):
    """{name: (best key, its rank, worst key, its rank, of how many)} over the columns
    that count (all but the worst-case instructions, which follow the mean)."""
    keys = [c[0] for c in COLUMNS if c[4]]
    rk = {k: ranks(val, k) for k in keys}
    out = {}
    for n in names:
        pos = []
        for k in keys:
            if n in rk[k]:
                tot = len(rk[k])
                pos.append(((rk[k][n] - 1) / max(tot - 1, 1), k, rk[k][n], tot))
        if not pos:
            continue
        b = min(pos, key=lambda p: (p[0], keys.index(p[1])))
        wst = max(pos, key=lambda p: (p[0], -keys.index(p[1])))
        out[n] = (b[1], b[2], b[3], wst[1], wst[2], wst[3])
    return out


def ordinal(k):
    return "%d%s" % (k, "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(
        k % 10, "th"))


def usable(val, names):
    """The controllers that hold the mean torque within USABLE_SSE of the reference."""
    return [n for n in names if val[n].get("sse") is not None and val[n]["sse"] <= USABLE_SSE]


def sentences(val, note, names):
    """The "use X for Y" sentences, among the usable controllers: per column the best
    (with those within TIE of it), then the all-round choice: the best mean rank over
    the quality columns among the controllers that never trip and are in no column's
    worst third, and the same among the third with the fewest instructions."""
    out = []
    ok = usable(val, names)
    for key, head, fmtx, purpose, _ in COLUMNS:
        xs = sorted((val[n][key], n) for n in ok
                    if val[n].get(key) is not None and val[n][key] != math.inf)
        if not xs:
            continue
        best_x, best = xs[0]
        ties = [n for x, n in xs[1:] if x <= best_x * (1 + TIE) + 1e-12]
        med = xs[len(xs) // 2][0]
        tie_txt = f" (within {TIE * 100:.0f} %: {', '.join(ties)})" if ties else ""
        unit = UNITS[key]
        vs = f" (median {fmtx.format(med)}{unit})" if med > best_x else ""
        out.append(f"Use **{best}** for {purpose}: {fmtx.format(best_x)}{unit}{vs}{tie_txt}.")
    rk = {k: ranks(val, k) for k in QUALITY + COST}

    def pos(n, k):
        return (rk[k][n] - 1) / max(len(rk[k]) - 1, 1) if n in rk[k] else None

    def allround(pool):
        """(mean position over QUALITY, name) of the pool's controllers that never trip,
        have every quality column and are in no column's worst third."""
        cand = []
        for n in pool:
            ps = [pos(n, k) for k in QUALITY]
            if None in ps or any(val[n][k] == math.inf for k in QUALITY) or max(ps) > 2 / 3:
                continue
            cand.append((sum(ps) / len(ps), n))
        return min(cand) if cand else None

    def cost_txt(n):
        parts = []
        if val[n].get("cpu_mean") is not None:
            parts.append(f"{val[n]['cpu_mean']:.0f} instructions per period")
        if val[n].get("flash") is not None:
            parts.append(f"{val[n]['flash']:.0f} B of flash")
        return ("; its cost " + ", ".join(parts)) if parts else ""

    def strong(n):
        return [SHORT[k] for k in QUALITY if pos(n, k) is not None and pos(n, k) < 1 / 3]

    pick = allround(ok)
    if pick:
        p, n = pick
        out.append(f"Use **{n}** as the all-round choice: the best mean rank over the "
                   f"{len(QUALITY)} quality columns ({', '.join(SHORT[k] for k in QUALITY)}) "
                   f"among the controllers that never trip and are in no column's worst "
                   f"third; in the best third for {', '.join(strong(n)) or 'none'}"
                   f"{cost_txt(n)}.")
    if "cpu_mean" in rk and rk["cpu_mean"]:
        cheap = [n for n in ok if pos(n, "cpu_mean") is not None and pos(n, "cpu_mean") <= 1 / 3]
        small = allround(cheap)
        if small and (not pick or small[1] != pick[1]):
            p, n = small
            out.append(f"On a small processor (the third of the controllers with the fewest "
                       f"instructions per period) use **{n}**: the best mean rank over the "
                       f"quality columns among them; in the best third for "
                       f"{', '.join(strong(n)) or 'none'}{cost_txt(n)}.")
    return out


def section(names, results, speeds, fav, dyn, bench, n_tunables):
    """The report's first section (Markdown lines)."""
    val, note = values(names, results, speeds, fav, dyn, bench, n_tunables)
    bw = best_worst(val, names)
    L = ["## Which controller for which job\n",
         "Every number below is measured by this report's runs (thesis SPMSM, 1.8 N·m) or by "
         "`./tools/bench` (Cortex-M4 instructions per PWM interrupt and flash, "
         + ("from `out/bench.json`" if bench else "**not measured: run ./tools/bench**")
         + "); lower is better in every column. *Best* and *worst* name the column where the "
         "controller ranks highest and lowest among those measured (the worst-case "
         "instructions follow the mean and are left out). The sentences after the table are "
         "derived from it by `tools/decide.py`.\n"]
    heads = ["controller", "best at", "worst at"] + [c[1] for c in COLUMNS]
    L.append("| " + " | ".join(heads) + " |")
    L.append("|" + "---|" * len(heads))
    for n in names:
        v = val[n]
        if n in bw:
            bk, br, bt, wk, wr, wt = bw[n]
            best = f"{SHORT[bk]} ({ordinal(br)} of {bt})"
            worst = f"{SHORT[wk]} ({ordinal(wr)} of {wt})"
        else:
            best = worst = "n/a"
        cells = [cell(v, c[0]) for c in COLUMNS]
        L.append(f"| {n} | {best} | {worst} | " + " | ".join(cells) + " |")
    L.append("")
    out = [n for n in names if n not in usable(val, names)]
    L.append(f"The sentences weigh only the controllers that hold the mean torque within "
             f"{USABLE_SSE:g} % of the reference (|T_sse| ≤ {USABLE_SSE:g} %, the threshold of "
             "the steady-state errors below)"
             + (f"; not {', '.join(out)}." if out else ": all of them.") + "\n")
    L += [f"- {s}" for s in sentences(val, note, names)]
    notes = []
    for n in names:
        for k, why in note[n].items():
            if why and (val[n].get(k) in (None, math.inf) or k == "ripple"):
                notes.append(f"{n}: {SHORT[k]} — {why}")
    L.append("")
    L.append("How each column is measured: " + "; ".join([
        f"T_rip and THD_I interpolated at f_av = {FAV_HZ / 1e3:g} kHz on each controller's fs "
        "sweep (geometric mean of " + " and ".join(f"{r}" for r in speeds) + " r/min)",
        "the step: the dynamic test's 0 → 2 N·m, time to 90 %",
        "|T_sse|: mean over the speeds at the default fs, % of 1.8 N·m",
        f"±20 % params: the controller configured with Rs, L (Ld and Lq) or ψpm 20 % low "
        f"and 20 % high (`--control-machine`, the plant true), {ROBUST_RPM} r/min, the largest "
        "shift of the mean torque from the controller's nominal run among the six",
        "sensorless: `--sensorless`, free rotor from standstill to 300 and 800 r/min and a "
        "1.8 N·m load step, the observer's angle error rms over the run (the forced start's "
        "first swing included)",
        "instructions and flash: `./tools/bench` (docs/bench.md)",
        "tunables: `./tools/sim --list-tunables`"]) + ".\n")
    if notes:
        L.append("Notes: " + "; ".join(notes) + ".\n")
    return L, val
