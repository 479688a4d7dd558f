"""The report of a declarative study (tools/study): OUT/NAME.md and OUT/NAME.png.

Per controller, machine and operating point the distribution of each metric over
the drawn units (5th percentile, median, 95th, worst) beside the nominal unit's
value; the worst case of each metric and controller named with its parameters;
every run that faulted or was refused, with its reason.
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import study_spec as ss  # noqa: E402

SHORT = {"rs": ("Rs", "%"), "l": ("L", "%"), "ld": ("Ld", "%"), "lq": ("Lq", "%"),
         "psi_pm": ("ψpm", "%"), "inertia": ("J", "%"), "friction_nms": ("B", "N·m·s"),
         "encoder_offset_deg": ("encoder", "°"), "dead_time_ns": ("dead time", "ns"),
         "current_gain": ("gain", "%")}


def fmt(x, f="{:+.2f}"):
    return "n/a" if x is None else f.format(x).replace("-", "−")


def describe_dist(p, d):
    kind = ss.PARAMS[p][0]
    sc, unit = (100.0, " %") if kind == "rel" or p == "current_gain" else (1.0, f" {SHORT[p][1]}")
    if d["dist"] == "fixed":
        return f"fixed {d['value'] * sc:g}{unit}"
    if d["dist"] == "uniform":
        if kind == "rel" or p == "current_gain":
            if d["lo"] == -d["hi"]:
                return f"uniform ±{d['hi'] * sc:g}{unit}"
        return f"uniform {d['lo'] * sc:g} … {d['hi'] * sc:g}{unit}"
    return (f"normal, mean {d['mean'] * sc:g}{unit}, sd {d['sd'] * sc:g}{unit}, truncated to "
            f"{d['lo'] * sc:g} … {d['hi'] * sc:g}{unit}")


def col_name(col):
    """A table column's short name (current_gain_b: gain b)."""
    if col.startswith("current_gain_"):
        return f"gain {col[-1]}"
    return SHORT[col][0] if col in SHORT else col


def describe_unit(spec, params, unit=None):
    if unit == 0:
        return "nominal (every distribution at its centre)"
    parts = []
    for p in spec.spread:
        v = params.get(p)
        name, unit = SHORT[p]
        if p == "current_gain":
            parts.append("gains " + "/".join(f"{100 * x:+.1f}" for x in v) + " %")
        elif v is None:
            continue
        elif ss.PARAMS[p][0] == "rel":
            parts.append(f"{name} {100 * v:+.1f} %")
        elif unit == "°":
            parts.append(f"{name} {v:+.2f}°")
        else:
            parts.append(f"{name} {v:.0f} {unit}")
    return ", ".join(parts).replace("-", "−")


def groups(spec, rows):
    """{(controller, machine key, point index): [(case, res, metrics)]} in order."""
    out = {}
    for row in rows:
        c = row[0]
        out.setdefault((c.ctrl, c.mkey, c.pt["index"]), []).append(row)
    return out


def stats(vals):
    v = np.array([x for x in vals if x is not None], dtype=float)
    if v.size == 0:
        return None
    return {"n": int(v.size), "p5": float(np.percentile(v, 5)), "median": float(np.median(v)),
            "p95": float(np.percentile(v, 95)), "min": float(v.min()), "max": float(v.max())}


def worst_of(metric, rows):
    """(value, row) of the worst case: the largest magnitude or the largest value."""
    how = ss.METRICS[metric][4]
    cand = [(r[2][metric], r) for r in rows if r[2].get(metric) is not None]
    if not cand:
        return None
    return max(cand, key=lambda t: abs(t[0]) if how == "abs" else t[0])


def spread_of(spec, p):
    """(column, range of the parameter's spread) per table column."""
    d = spec.spread[p]
    rng = 0.0 if d["dist"] == "fixed" else d["hi"] - d["lo"]
    cols = [f"current_gain_{x}" for x in "abc"] if p == "current_gain" else [p]
    return [(c, rng) for c in cols]


def sensitivities(spec, rows, metric):
    """Per group (controller, machine, point): a linear least-squares fit of the
    metric on the drawn units' parameters; each parameter's effect is its slope
    times the width of its spread (the change from one end of the spread to the
    other, the others held), with R^2 of the fit. None where there are too few
    units or no spread."""
    cols = [c for p in spec.spread for c in spread_of(spec, p) if c[1] > 0]
    out = {}
    for key, g in groups(spec, rows).items():
        pts = [(r[0], r[2][metric]) for r in g if r[0].unit > 0 and r[2].get(metric) is not None]
        if len(pts) < len(cols) + 3 or not cols:
            continue
        X = np.array([[float(v) for v in ss.param_values(spec, c)] for c, _ in pts], dtype=float)
        names = ss.param_columns(spec)
        idx = [names.index(c) for c, _ in cols]
        X = X[:, idx]
        y = np.array([v for _, v in pts], dtype=float)
        A = np.c_[X, np.ones(len(y))]
        coef, *_ = np.linalg.lstsq(A, y, rcond=None)
        sst = float(((y - y.mean()) ** 2).sum())
        r2 = 1.0 - float(((y - A @ coef) ** 2).sum()) / sst if sst > 0 else None
        eff = sorted(((c, float(b) * w) for (c, w), b in zip(cols, coef[:-1])),
                     key=lambda t: -abs(t[1]))
        out[key] = (r2, eff)
    return out


def plot(spec, rows, out):
    G = groups(spec, rows)
    mets = [m for m in spec.metrics if any(r[2].get(m) is not None for r in rows)]
    if not mets:
        return None
    mk = list(spec.machines)
    fig, ax = plt.subplots(len(mets), len(mk), figsize=(6.5 * len(mk), 3.3 * len(mets)),
                           squeeze=False)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, met in enumerate(mets):
        modes = ss.METRICS[met][0]
        pts = [p for p in spec.points if p["mode"] in modes]
        for j, m in enumerate(mk):
            a = ax[i, j]
            data, pos, cols, ticks, labels = [], [], [], [], []
            x = 0
            for p in pts:
                for k, c in enumerate(spec.controllers):
                    vals = [r[2][met] for r in G.get((c, m, p["index"]), [])
                            if r[0].unit > 0 and r[2][met] is not None]
                    data.append(vals if vals else [np.nan])
                    pos.append(x)
                    cols.append(colors[k % len(colors)])
                    x += 1
                ticks.append(x - (len(spec.controllers) + 1) / 2)
                lab = G.get((spec.controllers[0], m, p["index"]), [None])[0]
                labels.append(lab[0].label if lab else "")
                x += 1
            bp = a.boxplot(data, positions=pos, widths=0.7, whis=(5, 95), sym=".",
                           patch_artist=True)
            for patch, col in zip(bp["boxes"], cols):
                patch.set_facecolor(col)
                patch.set_alpha(0.5)
            a.set_xticks(ticks)
            a.set_xticklabels(labels, fontsize=8)
            a.axhline(0, color="grey", lw=0.5)
            a.set_ylabel(f"{met} ({ss.METRICS[met][2]})", fontsize=8)
            a.set_title(f"{spec.machines[m].name}", fontsize=9)
            a.grid(True, axis="y", lw=0.3)
    handles = [plt.Rectangle((0, 0), 1, 1, color=colors[k % len(colors)], alpha=0.5)
               for k in range(len(spec.controllers))]
    fig.legend(handles, spec.controllers, loc="upper right", ncol=len(spec.controllers),
               fontsize=8)
    fig.suptitle(f"{spec.title}: boxes 25–75 %, whiskers 5–95 % over the drawn units", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fn = f"{spec.name}.png"
    fig.savefig(os.path.join(out, fn), dpi=80)
    plt.close(fig)
    return fn


def write(spec, rows, info, out):
    """Write OUT/NAME.md (and its plot); returns its path."""
    G = groups(spec, rows)
    n_units = info["samples"]
    L = []
    w = L.append
    w(f"# {spec.title}\n")
    w(f"Written by `tools/study {info['file']}`"
      + (f" --samples {n_units}" if n_units != spec.samples else "")
      + f": {len(rows)} runs ({len(spec.machines)} machine(s) × {n_units + 1} units × "
      f"{len(spec.controllers)} controllers × {len(spec.points)} operating points), "
      f"{info['computed']} computed in {info['wall_s']:.0f} s wall ({info['how']}), "
      f"simulator CPU {info['sim_cpu_s']:.0f} s; simulator build {info['build'][:12]}. "
      f"Unit 0 of each machine is the nominal one (every distribution at its centre), units "
      f"1–{n_units} are drawn (seed {spec.seed}); the distributions are over the drawn units. "
      f"The plant is the unit; the drive is configured with the nominal machine file. "
      f"Every run: [{spec.name}.csv]({spec.name}.csv).\n")
    bad = [r for r in rows if r[1].status != "ok"]
    # ---- findings
    w("## Findings\n")
    for c in spec.controllers:
        rc = [r for r in rows if r[0].ctrl == c]
        parts = []
        for met in spec.metrics:
            wv = worst_of(met, [r for r in rc])
            if wv is None:
                continue
            st = stats([r[2][met] for r in rc if r[0].unit > 0])
            v, row = wv
            parts.append(f"{ss.METRICS[met][3].split(',')[0]}: 5–95 % {fmt(st['p5'])} … "
                         f"{fmt(st['p95'])} {ss.METRICS[met][2]}, worst {fmt(v)} "
                         f"({row[0].machine.name}, {row[0].label}, unit {row[0].unit})"
                         if st else f"{met}: n/a")
        nb = [r for r in rc if r[1].status != "ok"]
        fails = (f"; **{len(nb)} of {len(rc)} runs without indices** "
                 f"({', '.join(sorted({r[1].status for r in nb}))}, listed below)" if nb else
                 f"; all {len(rc)} runs completed without a fault")
        w(f"- **{c}** — " + "; ".join(parts) + fails + ".")
    w("")
    # ---- spread
    w("## The production spread\n")
    w("| parameter | distribution | nominal unit | acts on |")
    w("|---|---|---|---|")
    for p, d in spec.spread.items():
        nom = ss.centre(d)
        kind = ss.PARAMS[p][0]
        nomt = (f"{100 * nom:+g} %" if kind == "rel" or p == "current_gain" else
                f"{nom:g} {SHORT[p][1]}")
        w(f"| {SHORT[p][0]} (`{p}`) | {describe_dist(p, d)} | {nomt} | {ss.PARAMS[p][3]} |")
    if not spec.spread:
        w("| — | no spread: every unit is the nominal machine | | |")
    w("")
    if spec.comp_dead_time_ns is not None:
        w(f"The drive's dead-time compensation assumes {spec.comp_dead_time_ns:g} ns "
          "(`--comp-dead-time-ns`) whatever the unit's dead time.\n")
    # ---- points
    w("## Operating points\n")
    w("| point | mode | machine | speed (r/min) | torque or load step (N·m) | simulated (s) | "
      "window (s) |")
    w("|---|---|---|---|---|---|---|")
    for p in spec.points:
        for m in spec.machines.values():
            pv = ss.point_values(p, m)
            tl = pv.get("torque_nm", pv.get("load_nm"))
            extra = f" at {p['step_s']:g} s" if p["mode"] == "speed" else ""
            w(f"| {ss.point_label(p, pv)} | {p['mode']} | {m.name} | {pv['speed_rpm']:g} | "
              f"{tl:.4g}{extra} | {p['duration_s']:g} | {p['window_s'][0]:g}–{p['window_s'][1]:g} |")
    w("")
    w("Metrics: " + "; ".join(f"`{k}` {ss.METRICS[k][3]}" for k in spec.metrics) + ".\n")
    # ---- distributions
    w("## Distributions per controller\n")
    fig = plot(spec, rows, out)
    if fig:
        w(f"![{spec.title}: distributions]({fig})\n")
    for met in spec.metrics:
        modes, _, unit, what, _ = ss.METRICS[met]
        keys = [k for k in G if next(p for p in spec.points if p["index"] == k[2])["mode"]
                in modes]
        if not keys:
            continue
        w(f"### {what} (`{met}`, {unit})\n")
        w("| controller | machine | point | nominal | 5 % | median | 95 % | worst | units |")
        w("|---|---|---|---|---|---|---|---|---|")
        for c in spec.controllers:
            for k in keys:
                if k[0] != c:
                    continue
                g = G[k]
                nom = next((r[2][met] for r in g if r[0].unit == 0), None)
                st = stats([r[2][met] for r in g if r[0].unit > 0])
                wv = worst_of(met, g)
                lab = g[0][0].label
                if st is None:
                    w(f"| {c} | {g[0][0].machine.name} | {lab} | {fmt(nom)} | n/a | n/a | n/a | "
                      f"{fmt(wv[0]) if wv else 'n/a'} | 0 |")
                    continue
                w(f"| {c} | {g[0][0].machine.name} | {lab} | {fmt(nom)} | {fmt(st['p5'])} | "
                  f"{fmt(st['median'])} | {fmt(st['p95'])} | **{fmt(wv[0])}** (unit "
                  f"{wv[1][0].unit}) | {st['n']} |")
        w("")
    # ---- sensitivities
    sens_mets = [m for m in spec.metrics if ss.METRICS[m][4] == "abs" or m == "torque_ripple_pct"]
    if spec.spread and sens_mets:
        w("## What moves them\n")
        w("A linear fit of each metric on the drawn units' parameters, per controller, machine "
          "and point: each parameter's effect is the change of the metric from one end of its "
          "spread to the other (the fit's slope times the spread's width), the three largest "
          "shown; R² tells how much of the spread the linear fit explains.\n")
        for met in sens_mets:
            sens = sensitivities(spec, rows, met)
            if not sens:
                continue
            w(f"**{ss.METRICS[met][3]}** (`{met}`, {ss.METRICS[met][2]}):\n")
            w("| controller | machine | point | R² | largest effects across the spread |")
            w("|---|---|---|---|---|")
            for (c, m, pi), (r2, eff) in sens.items():
                g = groups(spec, rows)[(c, m, pi)]
                w(f"| {c} | {g[0][0].machine.name} | {g[0][0].label} | "
                  f"{'n/a' if r2 is None else f'{r2:.2f}'} | "
                  + ", ".join(f"{col_name(n)} {fmt(e)}" for n, e in eff[:3]) + " |")
            w("")
    # ---- worst cases
    w("## Worst cases\n")
    w("| controller | metric | value | machine | point | unit | its parameters |")
    w("|---|---|---|---|---|---|---|")
    for c in spec.controllers:
        for met in spec.metrics:
            wv = worst_of(met, [r for r in rows if r[0].ctrl == c])
            if wv is None:
                continue
            v, (case, _, _) = wv
            w(f"| {c} | `{met}` | {fmt(v)} {ss.METRICS[met][2]} | {case.machine.name} | "
              f"{case.label} | {case.unit} | {describe_unit(spec, case.params, case.unit) or 'nominal'} |")
    w("")
    # ---- failures
    w("## Runs without indices\n")
    if not bad:
        w("None: every run completed without a fault.\n")
    else:
        w("A run that faulted (tripped) or that the simulator refused is a result with its "
          "reason; its metrics are left out of the distributions above.\n")
        w("| controller | machine | point | unit | status | reason | its parameters |")
        w("|---|---|---|---|---|---|---|")
        for case, res, _ in bad[:200]:
            w(f"| {case.ctrl} | {case.machine.name} | {case.label} | {case.unit} | {res.status} "
              f"| {res.reason} | {describe_unit(spec, case.params, case.unit) or 'nominal'} |")
        if len(bad) > 200:
            w(f"\n… and {len(bad) - 200} more ({spec.name}.csv).")
        w("")
    path = os.path.join(out, f"{spec.name}.md")
    with open(path, "w") as f:
        f.write("\n".join(L) + "\n")
    return path
