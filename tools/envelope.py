#!/usr/bin/env -S /usr/bin/python3
"""Theoretical torque-speed envelope of a PMSM under a current and a voltage limit.

Steady state of the linear dq model (thesis (3.9)-(3.10)), SI units, electrical speed w:
    v_d = Rs i_d - w Lq i_q,   v_q = Rs i_q + w (Ld i_d + psi_pm)
    T   = 1.5 p (psi_pm i_q + (Ld - Lq) i_d i_q)
    |i| <= I_max  (current circle),   |v| <= V_max  (voltage ellipse, Rs included)
The envelope T_max(w) is the largest torque of a current vector inside both limits.
For each i_d the torque is linear in i_q (its coefficient psi_pm + (Ld - Lq) i_d is
positive for Ld <= Lq and i_d <= 0) and |v|^2 is a convex quadratic in i_q, so the
best i_q is the end of an interval found in closed form; the best i_d is found on a
grid and refined by golden-section search. The operating point is classified:
  "mtpa"  current limit only (the MTPA point at I_max: below base speed),
  "fw"    current and voltage limits both active (field weakening),
  "mtpv"  voltage limit only (maximum torque per voltage, IPMSM with
          psi_pm / Ld < I_max at high speed),
  "none"  no torque possible (above the SPMSM's maximum speed).
Defaults (the drive's field-weakening limits): I_max = the rated current, V_max = 92 % of Vdc/sqrt(3)
(the space-vector modulation's linear limit with a margin for the current control).

Closed forms (Rs = 0) that --selftest checks the numerical solution against:
  MTPA (IPMSM): i_d = (psi - sqrt(psi^2 + 8 (Lq-Ld)^2 I^2)) / (4 (Lq-Ld)); SPMSM i_d = 0
  base speed: w_b = V / |psi_s(MTPA at I_max)|
  current circle and flux circle psi_s = V/w:
      (Ld^2 - Lq^2) i_d^2 + 2 Ld psi i_d + psi^2 + Lq^2 I^2 - psi_s^2 = 0
  MTPV on the flux circle psi_s (c1 = psi/Ld, c2 = 1/Ld - 1/Lq):
      psi_d = (c1 - sqrt(c1^2 + 8 c2^2 psi_s^2)) / (4 c2)  (SPMSM: psi_d = 0)
  SPMSM maximum speed (psi > L I): w_max = V / (psi - L I).

usage:
  tools/envelope.py --machine FILE [--current-a A] [--vfrac F] [--rpm R ...]
                    [--plot OUT.png] [--json OUT.json]
  tools/envelope.py --selftest
"""
import argparse
import configparser
import json
import math
import sys
from dataclasses import dataclass

V_FRAC_DEFAULT = 0.92  # of Vdc/sqrt(3): the drive's field-weakening voltage limit


@dataclass
class Machine:
    name: str
    p: int
    rs: float  # ohm
    ld: float  # H
    lq: float  # H
    psi: float  # Wb
    vdc: float  # V
    i_rated: float  # A peak
    speed_rated_rpm: float
    torque_rated: float  # N*m
    speed_max_rpm: float = 0.0  # 0 = not declared


def load_machine(path):
    cp = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
    if not cp.read(path):
        raise SystemExit(f"envelope: cannot read {path}")
    g = lambda s, k: cp.getfloat(s, k)  # noqa: E731
    return Machine(name=cp.get("machine", "name"), p=cp.getint("machine", "pole_pairs"),
                   rs=g("machine", "rs_ohm"), ld=g("machine", "ld_mh") * 1e-3,
                   lq=g("machine", "lq_mh") * 1e-3, psi=g("machine", "psi_pm_wb"),
                   vdc=g("inverter", "vdc_v"), i_rated=g("rated", "current_a"),
                   speed_rated_rpm=g("rated", "speed_rpm"), torque_rated=g("rated", "torque_nm"),
                   speed_max_rpm=cp.getfloat("rated", "speed_max_rpm", fallback=0.0))


@dataclass
class Limits:
    i_max: float  # A peak
    v_max: float  # V peak phase


def default_limits(m, i_max=None, v_frac=V_FRAC_DEFAULT):
    return Limits(i_max=m.i_rated if i_max is None else i_max,
                  v_max=v_frac * m.vdc / math.sqrt(3.0))


def rpm_to_we(m, rpm):
    return rpm * 2.0 * math.pi / 60.0 * m.p


def we_to_rpm(m, w):
    return w * 60.0 / (2.0 * math.pi * m.p)


def torque(m, i_d, i_q):
    return 1.5 * m.p * (m.psi * i_q + (m.ld - m.lq) * i_d * i_q)


def voltage(m, w, i_d, i_q):
    vd = m.rs * i_d - w * m.lq * i_q
    vq = m.rs * i_q + w * (m.ld * i_d + m.psi)
    return math.hypot(vd, vq)


def iq_voltage_bound(m, w, i_d, v_max, sign):
    """The i_q of largest |i_q| with sign `sign` for which |v| <= v_max at (w, i_d),
    or None when no i_q of that sign (or 0) satisfies it."""
    a = m.rs ** 2 + (w * m.lq) ** 2
    b = 2.0 * (-m.rs * i_d * w * m.lq + m.rs * w * (m.ld * i_d + m.psi))
    c = (m.rs * i_d) ** 2 + (w * (m.ld * i_d + m.psi)) ** 2 - v_max ** 2
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return None
    r = math.sqrt(disc)
    lo, hi = (-b - r) / (2.0 * a), (-b + r) / (2.0 * a)
    if sign > 0:
        return hi if hi >= 0.0 else None
    return lo if lo <= 0.0 else None


def _best_iq(m, lim, w, i_d, sign):
    """(torque * sign, i_q) of the largest |T| of sign `sign` at this i_d, or None."""
    ic = lim.i_max ** 2 - i_d ** 2
    if ic < 0.0:
        return None
    iq_c = math.sqrt(ic) * sign
    iq_v = iq_voltage_bound(m, w, i_d, lim.v_max, sign)
    if iq_v is None:
        return None
    iq = min(iq_c, iq_v) if sign > 0 else max(iq_c, iq_v)
    # The voltage interval may also exclude small |i_q| (it need not contain 0):
    # then only the interval's end is feasible if it is inside the circle.
    if voltage(m, w, i_d, iq) > lim.v_max * (1.0 + 1e-9):
        return None
    return torque(m, i_d, iq) * sign, iq


@dataclass
class OpPoint:
    w: float  # electrical rad/s
    torque: float  # N*m (signed)
    i_d: float
    i_q: float
    region: str  # mtpa | fw | mtpv | none


def max_torque(m, lim, w, sign=+1, n_grid=4001):
    """Largest torque of sign `sign` (+1 motoring for w > 0, -1 braking) at electrical
    speed w inside both limits."""
    f = lambda i_d: _best_iq(m, lim, w, i_d, sign)  # noqa: E731
    ids = [-lim.i_max * (1.0 - k / (n_grid - 1)) for k in range(n_grid)]
    best, kbest = None, -1
    for k, i_d in enumerate(ids):
        r = f(i_d)
        if r is not None and (best is None or r[0] > best[0]):
            best, kbest = r, k
    if best is None or best[0] <= 0.0:
        return OpPoint(w, 0.0, 0.0, 0.0, "none")
    # Golden-section refinement in the neighbouring grid cells (unimodal there).
    a = ids[max(kbest - 1, 0)]
    b = ids[min(kbest + 1, n_grid - 1)]
    g = (math.sqrt(5.0) - 1.0) / 2.0

    def val(x):
        r = f(x)
        return -math.inf if r is None else r[0]
    x1, x2 = b - g * (b - a), a + g * (b - a)
    f1, f2 = val(x1), val(x2)
    for _ in range(80):
        if f1 < f2:
            a, x1, f1 = x1, x2, f2
            x2 = a + g * (b - a)
            f2 = val(x2)
        else:
            b, x2, f2 = x2, x1, f1
            x1 = b - g * (b - a)
            f1 = val(x1)
    i_d = x1 if f1 >= f2 else x2
    r = f(i_d)
    if r is None or r[0] < best[0]:
        i_d, r = ids[kbest], best
    i_q = r[1]
    at_i = math.hypot(i_d, i_q) >= lim.i_max * (1.0 - 1e-6)
    at_v = voltage(m, w, i_d, i_q) >= lim.v_max * (1.0 - 1e-6)
    region = "fw" if (at_i and at_v) else ("mtpv" if at_v else "mtpa")
    return OpPoint(w, r[0] * sign, i_d, i_q, region)


def mtpa_point(m, i):
    """MTPA current (i_d, i_q) at amplitude i (closed form)."""
    if abs(m.lq - m.ld) < 1e-15:
        return 0.0, i
    dl = m.lq - m.ld
    i_d = (m.psi - math.sqrt(m.psi ** 2 + 8.0 * dl * dl * i * i)) / (4.0 * dl)
    return i_d, math.sqrt(max(i * i - i_d * i_d, 0.0))


def base_speed(m, lim):
    """Electrical speed at which the MTPA point at I_max reaches the voltage limit."""
    i_d, i_q = mtpa_point(m, lim.i_max)
    a = (m.lq * i_q) ** 2 + (m.ld * i_d + m.psi) ** 2
    b = 2.0 * m.rs * (-i_d * m.lq * i_q + i_q * (m.ld * i_d + m.psi))
    c = m.rs ** 2 * lim.i_max ** 2 - lim.v_max ** 2
    return (-b + math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)


def mtpv_flux_point(m, psi_s):
    """(i_d, i_q) of the largest torque on the flux circle |psi_s| (closed form)."""
    c1 = m.psi / m.ld
    c2 = 1.0 / m.ld - 1.0 / m.lq
    if abs(c2) < 1e-12:
        psi_d = 0.0
    else:
        psi_d = (c1 - math.sqrt(c1 * c1 + 8.0 * c2 * c2 * psi_s * psi_s)) / (4.0 * c2)
    psi_d = max(psi_d, -psi_s)
    psi_q = math.sqrt(max(psi_s * psi_s - psi_d * psi_d, 0.0))
    return (psi_d - m.psi) / m.ld, psi_q / m.lq


def current_flux_intersection(m, i, psi_s):
    """(i_d, i_q >= 0) on the current circle i and the flux circle psi_s (closed form
    of the quadratic in the module docstring); None if they do not meet."""
    a = m.ld ** 2 - m.lq ** 2
    b = 2.0 * m.ld * m.psi
    c = m.psi ** 2 + m.lq ** 2 * i * i - psi_s ** 2
    if abs(a) < 1e-15:
        i_d = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return None
        roots = [(-b + s * math.sqrt(disc)) / (2.0 * a) for s in (+1.0, -1.0)]
        roots = [r for r in roots if abs(r) <= i]
        if not roots:
            return None
        i_d = max(roots)  # the one nearer the q axis: the larger torque
    if abs(i_d) > i:
        return None
    return i_d, math.sqrt(i * i - i_d * i_d)


def envelope(m, lim, rpms, sign=+1):
    """max_torque at each speed (r/min, either sign) for torque of sign `sign`."""
    return [max_torque(m, lim, rpm_to_we(m, r), sign) for r in rpms]


def characteristic_current(m):
    return m.psi / m.ld


# ----------------------------------------------------------------------------------------
# Self-test against the closed forms (Rs = 0), run by ctest (fieldweak_envelope_py).
def _selftest():
    fails = []

    def near(name, got, want, rel=2e-4, abs_=1e-9):
        if not abs(got - want) <= max(rel * abs(want), abs_):
            fails.append(f"{name}: got {got:.9g}, want {want:.9g}")

    spm = Machine("spm", 4, 0.0, 6.552e-3, 6.552e-3, 0.09427, 220.0, 4.2, 3000.0, 2.4)
    ipm = Machine("ipm", 4, 0.0, 0.6e-3, 1.33e-3, 0.1875, 540.0, 400.0, 3000.0, 400.0)
    # SPMSM: constant torque, field weakening on the circle, maximum speed.
    lim = default_limits(spm)
    L, psi, I, V = spm.ld, spm.psi, lim.i_max, lim.v_max
    wb = V / math.hypot(psi, L * I)
    near("spm base speed", base_speed(spm, lim), wb)
    for x in (0.3, 0.9):
        near(f"spm T below base ({x})", max_torque(spm, lim, x * wb).torque, 1.5 * spm.p * psi * I)
        if max_torque(spm, lim, x * wb).region != "mtpa":
            fails.append(f"spm region below base ({x}) not mtpa")
    wmax = V / (psi - L * I)
    for x in (0.2, 0.5, 0.9):
        w = wb + x * (wmax - wb)
        i_d = ((V / w) ** 2 - psi ** 2 - (L * I) ** 2) / (2.0 * L * psi)
        op = max_torque(spm, lim, w)
        near(f"spm T in field weakening ({x})", op.torque,
             1.5 * spm.p * psi * math.sqrt(I * I - i_d * i_d), rel=5e-4)
        near(f"spm i_d in field weakening ({x})", op.i_d, i_d, rel=5e-4, abs_=1e-4)
        if op.region != "fw":
            fails.append(f"spm region in field weakening ({x}) = {op.region}")
    if max_torque(spm, lim, 1.01 * wmax).region != "none":
        fails.append("spm: torque above the maximum speed")
    # IPMSM: MTPA torque below base speed, circle-ellipse intersection, MTPV.
    lim = default_limits(ipm)
    i_d, i_q = mtpa_point(ipm, lim.i_max)
    wb = lim.v_max / math.hypot(ipm.ld * i_d + ipm.psi, ipm.lq * i_q)
    near("ipm base speed", base_speed(ipm, lim), wb)
    near("ipm T below base", max_torque(ipm, lim, 0.5 * wb).torque, torque(ipm, i_d, i_q))
    # MTPA is the maximum of T on the circle: a brute-force scan never beats it.
    scan = max(torque(ipm, lim.i_max * math.cos(b), lim.i_max * math.sin(b))
               for b in [math.pi / 2 + k * (math.pi / 2) / 20000 for k in range(20001)])
    near("ipm MTPA closed form vs scan", torque(ipm, i_d, i_q), scan, rel=1e-6)
    if characteristic_current(ipm) >= lim.i_max:
        fails.append("ipm test machine must have psi/Ld < I_max (MTPV region)")
    for w in (1.2 * wb, 1.5 * wb):
        op = max_torque(ipm, lim, w)
        x = current_flux_intersection(ipm, lim.i_max, lim.v_max / w)
        if op.region == "fw":
            near(f"ipm T at circle/ellipse w={w:.0f}", op.torque, torque(ipm, *x), rel=5e-4)
    w_hi = 4.0 * wb
    op = max_torque(ipm, lim, w_hi)
    i_d, i_q = mtpv_flux_point(ipm, lim.v_max / w_hi)
    near("ipm MTPV torque at 4 w_b", op.torque, torque(ipm, i_d, i_q), rel=5e-4)
    if op.region != "mtpv":
        fails.append(f"ipm region at 4 w_b = {op.region}, want mtpv")
    # MTPV closed form is the maximum on its flux circle (scan).
    psi_s = lim.v_max / w_hi
    best = 0.0
    for k in range(20001):
        d = math.pi / 2 + k * (math.pi / 2) / 20000
        pd, pq = psi_s * math.cos(d), psi_s * math.sin(d)
        best = max(best, torque(ipm, (pd - ipm.psi) / ipm.ld, pq / ipm.lq))
    near("ipm MTPV closed form vs scan", torque(ipm, i_d, i_q), best, rel=1e-6)
    # With Rs: the optimum satisfies both limits and no nearby feasible point is better.
    ipm_r = Machine("ipm_r", 4, 0.0075, 0.6e-3, 1.33e-3, 0.1875, 540.0, 400.0, 3000.0, 400.0)
    spm_r = Machine("spm_r", 4, 0.901, 6.552e-3, 6.552e-3, 0.09427, 220.0, 4.2, 3000.0, 2.4)
    for mm in (ipm_r, spm_r):
        lm = default_limits(mm)
        for rpm in (1000.0, 3000.0, 3750.0, 6000.0):
            w = rpm_to_we(mm, rpm)
            op = max_torque(mm, lm, w)
            if op.region == "none":
                continue
            if math.hypot(op.i_d, op.i_q) > lm.i_max * (1 + 1e-6) or \
                    voltage(mm, w, op.i_d, op.i_q) > lm.v_max * (1 + 1e-6):
                fails.append(f"{mm.name} {rpm}: optimum outside the limits")
            for dd in (-1e-3, 1e-3):
                for dq in (-1e-3, 1e-3):
                    a, b = op.i_d + dd * lm.i_max, op.i_q + dq * lm.i_max
                    if math.hypot(a, b) <= lm.i_max and voltage(mm, w, a, b) <= lm.v_max and \
                            torque(mm, a, b) > op.torque * (1 + 1e-6):
                        fails.append(f"{mm.name} {rpm}: a feasible neighbour is better")
    # Braking (sign -1) at the same speed gives at least the motoring magnitude when
    # Rs > 0 (the resistive drop then reduces the terminal voltage).
    lm = default_limits(spm_r)
    w = rpm_to_we(spm_r, 3750.0)
    if -max_torque(spm_r, lm, w, -1).torque < max_torque(spm_r, lm, w, +1).torque:
        fails.append("spm_r: braking envelope below the motoring one at 3750 r/min")
    for f in fails:
        print("FAIL", f)
    print(f"envelope selftest: {'FAIL' if fails else 'ok'} ({len(fails)} failures)")
    return 1 if fails else 0


def plot(m, lim, path, rpm_max=None, extra=None):
    """Torque-speed envelope (regions coloured) and the dq current plane (circle,
    voltage ellipses at a few speeds, MTPA and MTPV loci). extra: {label: [(rpm,
    torque, ok), ...]} achieved points to overlay on the torque-speed plot."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    wb = base_speed(m, lim)
    rpm_max = rpm_max or 2.2 * we_to_rpm(m, wb)
    rpms = [rpm_max * k / 300 for k in range(1, 301)]
    ops = [max_torque(m, lim, rpm_to_we(m, r)) for r in rpms]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 5))
    colours = {"mtpa": "C0", "fw": "C1", "mtpv": "C2", "none": "0.5"}
    for reg, lab in (("mtpa", "current limit (MTPA)"), ("fw", "current circle + voltage ellipse"),
                     ("mtpv", "voltage limit (MTPV)")):
        xs = [r for r, o in zip(rpms, ops) if o.region == reg]
        ys = [o.torque for o in ops if o.region == reg]
        if xs:
            ax.plot(xs, ys, ".", ms=3, color=colours[reg], label=lab)
    ax.plot(rpms, [0.9 * o.torque for o in ops], "k--", lw=0.8, label="90 % of the envelope")
    for k, (lab, pts) in enumerate((extra or {}).items()):
        xs = [p[0] for p in pts]
        ys = [p[1] for p in pts]
        ax.plot(xs, ys, marker="os^vDx<>"[k % 8], ls=":", lw=0.8, label=lab)
        bad = [(p[0], p[1]) for p in pts if not p[2]]
        if bad:
            ax.plot([b[0] for b in bad], [b[1] for b in bad], "rx", ms=10, mew=2)
    ax.axvline(we_to_rpm(m, wb), color="0.6", lw=0.8)
    ax.set_xlabel("speed (r/min)")
    ax.set_ylabel("torque (N*m)")
    ax.set_title(f"{m.name}: I_max {lim.i_max:g} A, V_max {lim.v_max:.1f} V "
                 f"(MTPA corner at I_max: {we_to_rpm(m, wb):.0f} r/min)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    # dq plane
    th = [math.pi / 2 + k * math.pi / 2 / 200 for k in range(201)]
    bx.plot([lim.i_max * math.cos(t) for t in th], [lim.i_max * math.sin(t) for t in th], "k",
            label="current circle")
    for x in (1.0, 1.5, 2.0):
        w = x * wb
        pts = []
        for k in range(721):
            a = 2 * math.pi * k / 720
            # Rs = 0 ellipse: (Ld i_d + psi)^2 + (Lq i_q)^2 = (V/w)^2
            pts.append(((lim.v_max / w * math.cos(a) - m.psi) / m.ld, lim.v_max / w * math.sin(a) / m.lq))
        bx.plot([p[0] for p in pts], [p[1] for p in pts], lw=0.8, label=f"voltage ellipse {x:g} x base")
    mt = [mtpa_point(m, lim.i_max * k / 50) for k in range(51)]
    bx.plot([p[0] for p in mt], [p[1] for p in mt], "C0--", label="MTPA")
    if m.lq > m.ld and characteristic_current(m) < 2.0 * lim.i_max:
        mv = [mtpv_flux_point(m, m.psi * k / 50) for k in range(1, 51)]
        bx.plot([p[0] for p in mv], [p[1] for p in mv], "C2--", label="MTPV")
    bx.set_xlim(-1.6 * lim.i_max, 0.2 * lim.i_max)
    bx.set_ylim(0, 1.3 * lim.i_max)
    bx.set_aspect("equal")
    bx.set_xlabel("i_d (A)")
    bx.set_ylabel("i_q (A)")
    bx.grid(True, alpha=0.3)
    bx.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--machine")
    ap.add_argument("--current-a", type=float, help="current limit, A peak (default: rated)")
    ap.add_argument("--vfrac", type=float, default=V_FRAC_DEFAULT,
                    help="voltage limit as a fraction of Vdc/sqrt(3) (default 0.92)")
    ap.add_argument("--rpm", type=float, nargs="*", help="speeds to tabulate (r/min)")
    ap.add_argument("--plot")
    ap.add_argument("--json")
    ap.add_argument("--selftest", action="store_true")
    a = ap.parse_args()
    if a.selftest:
        return _selftest()
    if not a.machine:
        ap.error("--machine is required (or --selftest)")
    m = load_machine(a.machine)
    lim = default_limits(m, a.current_a, a.vfrac)
    wb = base_speed(m, lim)
    print(f"{m.name}: I_max {lim.i_max:g} A, V_max {lim.v_max:.2f} V, base speed "
          f"{we_to_rpm(m, wb):.0f} r/min, characteristic current psi/Ld {characteristic_current(m):.1f} A")
    rpms = a.rpm or [we_to_rpm(m, wb) * x for x in (0.5, 1.0, 1.5, 2.0)]
    rows = []
    for r in rpms:
        op = max_torque(m, lim, rpm_to_we(m, r))
        rows.append({"rpm": r, "torque_nm": op.torque, "id_a": op.i_d, "iq_a": op.i_q,
                     "region": op.region})
        print(f"  {r:8.0f} r/min  T_max {op.torque:9.3f} N*m  i_d {op.i_d:9.3f} A  "
              f"i_q {op.i_q:9.3f} A  {op.region}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"machine": m.name, "i_max_a": lim.i_max, "v_max_v": lim.v_max,
                       "base_rpm": we_to_rpm(m, wb), "points": rows}, f, indent=1)
    if a.plot:
        plot(m, lim, a.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
