#!/usr/bin/python3
"""Machine files with non-ideal mechanics from a shipped one (sim_host/README.md, "Mechanics").

    gen_nonideal.py BASE.ini OUT.ini [--stiction F] [--coulomb F] [--viscous F]
                    [--cogging F] [--harmonics A2,A3,...] [--cogging-phase DEG]
                    [--passive F] [--constant F] [--slots N] [--name NAME]
                    [--seed S [--spread X]]

Fractions F of the base's rated torque ([rated] torque_nm): stiction
(break-away), Coulomb (running) friction, viscous friction giving F of the rated
torque at the rated speed, cogging (peak of the whole cogging torque, all
harmonics together), passive or constant load. --harmonics: harmonics 2, 3, ...
of the cogging fundamental, relative to it. --slots: stator slots (default: the
base's; required if it has none). The base's other sections are kept, its
[mechanics] replaced (inertia kept).

--seed S makes an unseen variant: each given fraction is drawn uniformly in
[F/2, F] (stiction at least the drawn Coulomb friction), the cogging's phase in
[0, 360) degrees, harmonics 2 and 3 in [0, 0.3] and [0, 0.15] of the
fundamental with random phases unless given, the slots among the counts
divisible by 3 from 1.5 p to 12 p unless given; with --spread X also Rs, Ld,
Lq, psi_pm and J each scaled by a factor drawn in [1 - X, 1 + X] (Ld and Lq
by the same one if the base's are equal). Python's
random.Random(S): the same S gives the same file.

The shipped stress cases (sim_host/machines/nonideal/*_stress.ini) are
    gen_nonideal.py BASE.ini OUT.ini --stiction 0.15 --coulomb 0.10 --viscous 0.05
                    --cogging 0.10 --passive 0.20 [--slots N]
"""
import argparse
import math
import random
import re
import sys


def read_sections(text):
    """[(section or None, [lines])] in file order."""
    out, cur = [], (None, [])
    for ln in text.splitlines():
        m = re.match(r"\s*\[(\w+)\]\s*(;.*)?$", ln)
        if m:
            out.append(cur)
            cur = (m.group(1), [ln])
        else:
            cur[1].append(ln)
    out.append(cur)
    return out


def key(sections, sec, name):
    for s, lines in sections:
        if s != sec:
            continue
        for ln in lines:
            m = re.match(r"\s*%s\s*=\s*([^;#]*)" % re.escape(name), ln)
            if m:
                return m.group(1).strip()
    return None


def set_key(sections, sec, name, value):
    for i, (s, lines) in enumerate(sections):
        if s != sec:
            continue
        for j, ln in enumerate(lines):
            if re.match(r"\s*%s\s*=" % re.escape(name), ln):
                lines[j] = "%s = %s" % (name, value)
                return


def cogging_peak(amps, phases, n=4096):
    """Peak of sum_k a_k sin(k x + phi_k) over one period (sampled, then refined)."""
    best, xb = 0.0, 0.0
    for i in range(n):
        x = 2.0 * math.pi * i / n
        v = abs(sum(a * math.sin((k + 1) * x + p) for k, (a, p) in enumerate(zip(amps, phases))))
        if v > best:
            best, xb = v, x
    h = 2.0 * math.pi / n
    for _ in range(60):  # refine around the best sample, halving the step
        for x in (xb - h, xb + h):
            v = abs(sum(a * math.sin((k + 1) * x + p) for k, (a, p) in enumerate(zip(amps, phases))))
            if v > best:
                best, xb = v, x
        h *= 0.5
    return best


def fmt(v):
    return "%.6g" % v


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base")
    ap.add_argument("out")
    for k in ("stiction", "coulomb", "viscous", "cogging", "passive", "constant"):
        ap.add_argument("--" + k, type=float, default=0.0)
    ap.add_argument("--harmonics", default="")
    ap.add_argument("--cogging-phase", type=float, default=0.0)
    ap.add_argument("--slots", type=int, default=0)
    ap.add_argument("--name", default="")
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--spread", type=float, default=0.0)
    a = ap.parse_args(argv)
    for k in ("stiction", "coulomb", "viscous", "cogging", "passive"):
        v = getattr(a, k)
        if not (0.0 <= v <= 1.0):
            ap.error("--%s = %g out of range [0, 1] (a fraction of the rated torque)" % (k, v))
    if not (-1.0 <= a.constant <= 1.0):
        ap.error("--constant = %g out of range [-1, 1]" % a.constant)
    if not (0.0 <= a.spread < 1.0):
        ap.error("--spread = %g out of range [0, 1)" % a.spread)
    if a.passive > 0.0 and a.constant != 0.0:
        ap.error("--passive and --constant: a machine file has one load")
    with open(a.base) as f:
        text = f.read()
    secs = read_sections(text)
    t_rated = float(key(secs, "rated", "torque_nm"))
    w_rated = float(key(secs, "rated", "speed_rpm")) * 2.0 * math.pi / 60.0
    p = int(key(secs, "machine", "pole_pairs"))
    inertia = float(key(secs, "mechanics", "inertia_kgm2"))
    slots = a.slots or int(key(secs, "mechanics", "slots") or 0)
    rng = random.Random(a.seed) if a.seed is not None else None
    frac = {k: getattr(a, k) for k in ("stiction", "coulomb", "viscous", "cogging", "passive",
                                       "constant")}
    harm = [float(x) for x in a.harmonics.split(",") if x.strip()]
    harm_ph = [0.0] * len(harm)
    phase = math.radians(a.cogging_phase)
    if rng is not None:
        for k in frac:
            frac[k] *= rng.uniform(0.5, 1.0)
        phase = rng.uniform(0.0, 2.0 * math.pi)
        if not harm:
            harm = [rng.uniform(0.0, 0.3), rng.uniform(0.0, 0.15)]
        harm_ph = [rng.uniform(0.0, 2.0 * math.pi) for _ in harm]
        if not slots:
            cands = [s for s in range(3, 12 * p + 1, 3) if s >= 1.5 * p]
            slots = rng.choice(cands)
        if a.spread > 0.0:
            # a surface-magnet base (Ld = Lq) stays one: both take the same factor
            same_l = key(secs, "machine", "ld_mh") == key(secs, "machine", "lq_mh")
            f_l = None
            for sec, name in (("machine", "rs_ohm"), ("machine", "ld_mh"), ("machine", "lq_mh"),
                              ("machine", "psi_pm_wb"), ("mechanics", "inertia_kgm2")):
                f = rng.uniform(1.0 - a.spread, 1.0 + a.spread)
                if name == "lq_mh" and same_l:
                    f = f_l
                if name == "ld_mh":
                    f_l = f
                v = float(key(secs, sec, name)) * f
                set_key(secs, sec, name, fmt(v))
                if name == "inertia_kgm2":
                    inertia = v
    frac["stiction"] = max(frac["stiction"], frac["coulomb"])
    if frac["cogging"] > 0.0 and not slots:
        ap.error("--cogging needs --slots (the base has none)")
    name = a.name or (key(secs, "machine", "name") + ("_seed%d" % a.seed if rng else "_nonideal"))
    set_key(secs, "machine", "name", name)

    amps = [1.0] + harm
    phases = [phase] + harm_ph
    scale = frac["cogging"] * t_rated / cogging_peak(amps, phases) if frac["cogging"] > 0 else 0.0
    old = [ln for s, lines in secs if s == "mechanics" for ln in lines]
    keep = [ln for ln in old[1:] if re.match(r"\s*(;|$)", ln) is None and
            re.match(r"\s*(inertia_kgm2|friction_nms|coulomb_nm|stiction_nm|slots|cogging_\w+|load_\w+)\s*=",
                     ln) is None]
    if keep:
        sys.exit("gen_nonideal: unknown [mechanics] keys in %s: %s" % (a.base, keep))
    mech = ["[mechanics]",
            "; generated: sim_host/machines/gen_nonideal.py %s" % " ".join(argv[2:]),
            "; from %s; fractions of the rated torque %s N*m:" % (a.base.split("/")[-1], fmt(t_rated)),
            "; stiction %s, Coulomb %s, viscous %s at %s r/min, cogging peak %s, passive %s, "
            "constant %s" % (fmt(frac["stiction"]), fmt(frac["coulomb"]), fmt(frac["viscous"]),
                             fmt(w_rated * 60.0 / (2.0 * math.pi)), fmt(frac["cogging"]),
                             fmt(frac["passive"]), fmt(frac["constant"])),
            "inertia_kgm2 = %s" % fmt(inertia),
            "friction_nms = %s" % fmt(frac["viscous"] * t_rated / w_rated),
            "coulomb_nm = %s" % fmt(frac["coulomb"] * t_rated),
            "stiction_nm = %s" % fmt(frac["stiction"] * t_rated)]
    if slots:
        mech.append("slots = %d" % slots)
    if scale > 0.0:
        mech.append("cogging_nm = %s" % fmt(scale))
        mech.append("cogging_phase_deg = %s" % fmt(math.degrees(phase) % 360.0))
        if harm:
            mech.append("cogging_harmonics_nm = %s" % " ".join(fmt(h * scale) for h in harm))
            mech.append("cogging_harmonics_deg = %s" %
                        " ".join(fmt(math.degrees(x) % 360.0) for x in harm_ph))
    if frac["passive"] > 0.0:
        mech += ["load_kind = passive", "load_nm = %s" % fmt(frac["passive"] * t_rated)]
    elif frac["constant"] != 0.0:
        mech += ["load_kind = constant", "load_nm = %s" % fmt(frac["constant"] * t_rated)]
    out = []
    for s, lines in secs:
        if s == "mechanics":
            out += mech + [""]
        else:
            out += lines
    with open(a.out, "w") as f:
        f.write("\n".join(out).rstrip("\n") + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
