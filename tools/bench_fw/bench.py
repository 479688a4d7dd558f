#!/usr/bin/python3
"""Interrupt-cost benchmark and memory footprint of every registered controller.

Called by ./tools/bench (see docs/bench.md). Steps:
  1. build (host-release: bench_rec, bench_host; cm4: bench_cm4 and the
     footprint images) and the QEMU counting plugin (cc, no sanitizers);
  2. record a host closed loop per controller at 750 and 2250 r/min, 1.8 N*m;
  3. replay each recording through fw_isr on the emulated Cortex-M4 (QEMU with
     the plugin: exact instruction counts per call) and on the PC (wall time;
     callgrind instruction counts); shorter recordings through the same image
     built for ARMv6-M on QEMU's microbit (Cortex-M0): instructions and a
     Cortex-M0+ cycle range per call (cm0 preset flags, --no-cm0 skips it);
  4. footprint: per-controller image minus the baseline image;
  5. one table on stdout, everything in out/bench.json.
"""
import argparse
import concurrent.futures as cf
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from argtypes import number_in, whole_in  # noqa: E402
FW = os.path.join(ROOT, "tools", "bench_fw")
SPEEDS = (750, 2250)
TORQUE_NM = 1.8
SENSORLESS_RPM = 150  # 5 % of the thesis SPMSM's rated 3000 r/min (sensorless_config.h w_on)
# Section indices of the plugin's end markers (order of the end= arguments).
SECTIONS = ("empty", "boot", "run", "est", "step", "mid")
# The Cortex-M4 replay target: QEMU machine and where the recording is loaded.
CM4_TARGET = {"machine": "mps2-an386", "blob": 0x20200000}
MARKERS = ["bench_mark_begin"] + ["bench_mark_end_" + s for s in SECTIONS]
# ARMv6-M: QEMU microbit (Cortex-M0, the Cortex-M0+'s instruction set), the
# recording in the flash above the image (hal/qemu_microbit/qemu_microbit.h).
CM0_BLOB_ADDR = 0x30000
CM0_BLOB_MAX = 0x10000
# Whether a small MCU suffices: m2ptfc's worst interrupt within one 10 kHz period of
# a 64 MHz Cortex-M0+.
CM0_FIT = {"ctrl": "m2ptfc", "f_cpu_hz": 64000000, "f_pwm_hz": 10000}
# Thesis execution times (thesis Fig. 6.14), dSPACE DS1202 at 2 GHz, us.
THESIS_US = {"m2ptfc": 4.6, "m1": 6.96, "m2": 9.24, "m3": 4.8}


def log(msg):
    print("bench: " + msg, file=sys.stderr, flush=True)


def run(cmd, **kw):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if r.returncode != 0:
        sys.stderr.write(r.stdout[-4000:] + r.stderr[-4000:])
        raise SystemExit("bench: command failed (%d): %s" % (r.returncode, " ".join(cmd)))
    return r.stdout


def configure(build, preset_vars, toolchain=None, update=False):
    """Configures build once; update=True sets preset_vars again on an
    existing build (options that may have changed since)."""
    if not os.path.exists(os.path.join(build, "build.ninja")):
        cmd = ["cmake", "-S", ROOT, "-B", build, "-G", "Ninja"]
        if toolchain:
            cmd.append("-DCMAKE_TOOLCHAIN_FILE=" + toolchain)
        cmd += ["-D%s=%s" % kv for kv in preset_vars.items()]
        run(cmd)
    elif update:
        run(["cmake", "-S", ROOT, "-B", build] + ["-D%s=%s" % kv for kv in preset_vars.items()])


def build(args):
    host = args.host_build
    cm4 = args.cm4_build
    if not args.host_bin:
        configure(host, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2",
                         "CMAKE_CXX_FLAGS_RELEASE": "-O2", "PMSM_TARGET": "host",
                         "PMSM_SANITIZE": "OFF"})
    configure(cm4, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2 -g",
                    "CMAKE_CXX_FLAGS_RELEASE": "-O2 -g", "PMSM_TARGET": "cm4"},
              toolchain=os.path.join(ROOT, "tools", "cmake", "arm-none-eabi-cm4.cmake"))
    if args.host_bin:
        bdir = args.host_bin
    else:
        log("building host-release (bench_rec, bench_host) in " + host)
        run(["cmake", "--build", host, "-j2", "--target", "bench_rec", "bench_host"])
        bdir = os.path.join(host, "tests", "bench", "bench_fw")
    target = "bench_cm4_all" if not args.quick else "bench_cm4"
    log("building cm4 (%s) in %s" % (target, cm4))
    run(["cmake", "--build", cm4, "-j2", "--target", target])
    plugin = os.path.join(args.work, "bench_plugin.so")
    run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin,
         os.path.join(FW, "bench_plugin.c")])
    cdir = os.path.join(cm4, "tests", "bench", "bench_fw")
    tools = {"rec": os.path.join(bdir, "bench_rec"), "host": os.path.join(bdir, "bench_host"),
             "elf": os.path.join(cdir, "bench_cm4.elf"), "cdir": cdir, "plugin": plugin,
             **CM4_TARGET}
    if args.cm0:
        cm0 = args.cm0_build
        # (anti-cogging is left out by the cm0 target's default: the micro:bit's RAM
        # cannot hold its sums, control/CMakeLists.txt)
        configure(cm0, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2 -g",
                        "CMAKE_CXX_FLAGS_RELEASE": "-O2 -g", "PMSM_TARGET": "cm0"},
                  toolchain=os.path.join(ROOT, "tools", "cmake", "arm-none-eabi-cm0.cmake"),
                  update=True)
        log("building cm0 (bench_cm0) in " + cm0)
        run(["cmake", "--build", cm0, "-j2", "--target", "bench_cm0"])
        tools["cm0"] = dict(tools, elf=os.path.join(cm0, "tests", "bench", "bench_fw",
                                                    "bench_cm0.elf"),
                            machine="microbit", blob=CM0_BLOB_ADDR)
    return tools


def symbols(elf):
    """Functions of the image: {name: (start, size)} from nm (symbols without a
    size, e.g. libgcc's assembly routines, extend to the next symbol)."""
    out = run(["arm-none-eabi-nm", "-n", "-S", "--defined-only", elf])
    rows = []
    for line in out.splitlines():
        f = line.split()
        if len(f) == 4 and f[2] in "TtWw":
            rows.append((int(f[0], 16) & ~1, int(f[1], 16), f[3]))
        elif len(f) == 3 and f[1] in "TtWw" and not f[2].startswith("$"):
            rows.append((int(f[0], 16) & ~1, 0, f[2]))
    syms = {}
    for i, (a, size, name) in enumerate(rows):
        if size == 0:
            nxt = next((b for b, _, _ in rows[i + 1:] if b > a), a + 2)
            size = min(nxt - a, 4096)
        syms.setdefault(name, (a, size))
    return syms


def qemu_count(tools, syms_file, marks, rec, out_file, timeout=300, pcsec=None):
    """Runs the bench image on one recording with the counting plugin."""
    cm0 = tools["machine"] == "microbit"
    plugin = ",".join([tools["plugin"], "out=" + out_file, "begin=%x" % marks[0]] +
                      ["end=%x" % a for a in marks[1:]] + ["syms=" + syms_file] +
                      (["pcsec=%d" % pcsec] if pcsec is not None else []) +
                      (["cycles=m0plus"] if cm0 else []))
    cmd = ["timeout", str(timeout), "qemu-system-arm", "-machine", tools["machine"],
           "-display", "none", "-monitor", "none", "-serial", "stdio",
           "-semihosting-config", "enable=on,target=native",
           "-device", "loader,file=%s,addr=0x%x,force-raw=on" % (rec, tools["blob"]),
           "-plugin", plugin, "-kernel", tools["elf"]]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       stdin=subprocess.DEVNULL)
    line = next((l for l in r.stdout.splitlines() if l.startswith("bench:")), "")
    if r.returncode != 0:
        raise SystemExit("bench: QEMU replay of %s failed (%d): %s %s" %
                         (rec, r.returncode, line, r.stderr[-2000:]))
    sec = {s: [] for s in SECTIONS}
    cyc = {s: [] for s in SECTIONS}  # (cycles as taken, conditional branches)
    prof = {s: {} for s in SECTIONS}
    pcs = {}
    with open(out_file) as f:
        for l in f:
            p = l.split()
            if p[0] == "A":
                pcs[int(p[1], 16)] = int(p[2])
            elif p[0] == "S":
                sec[SECTIONS[int(p[1])]].append(int(p[2]))
            elif p[0] == "C":
                cyc[SECTIONS[int(p[1])]].append((int(p[2]), int(p[3])))
            elif p[0] == "F":
                prof[SECTIONS[int(p[1])]][p[2]] = (int(p[3]), int(p[4]))
    over = set(sec["empty"])
    if len(over) != 1:
        raise SystemExit("bench: marker overhead not constant: %s" % sorted(over))
    o = over.pop()
    res = {s: [v - o for v in sec[s]] for s in SECTIONS if s != "empty"}
    kv = dict(re.findall(r"(\w+) (\d+)", line.replace("bench: ", "")))
    if cm0:
        # the marker pair's own cycles: those of the empty windows
        co = set(cyc["empty"])
        if len(co) != 1:
            raise SystemExit("bench: marker cycles not constant: %s" % sorted(co))
        oc, ob = co.pop()
        cyc = {s: [(c - oc, b - ob) for c, b in cyc[s]] for s in SECTIONS if s != "empty"}
    return {"sections": res, "profile": prof, "overhead": o, "summary": kv,
            "raw": sec, "pcs": pcs, "cycles": cyc}


def symbols_file(elf, path):
    """Writes the image's functions for the plugin; returns (syms, marker addresses)."""
    syms = symbols(elf)
    with open(path, "w") as f:
        for name, (a, size) in syms.items():
            f.write("%x %d %s\n" % (a, size, name))
    return syms, [syms[m][0] for m in MARKERS]


def cm0_counts(args, tools, names, speeds, machine):
    """ARMv6-M: record shorter closed loops (the recording must fit the
    microbit's free flash), replay them on QEMU microbit; per controller the
    instructions and the Cortex-M0+ cycle range of fw_isr, estimator and step."""
    t = tools["cm0"]
    recdir = os.path.join(args.work, "rec_cm0")
    os.makedirs(recdir, exist_ok=True)
    jobs = [(n, s) for n in names for s in speeds]

    def record(job):
        n, s = job
        run([tools["rec"], "record", "--machine", machine, "--speed", str(s), "--torque",
             str(TORQUE_NM), "--periods", str(args.cm0_periods), "--outdir", recdir,
             "--ctrl", n])
        path = os.path.join(recdir, "%s_%d.bin" % job)
        if os.path.getsize(path) > CM0_BLOB_MAX:
            raise SystemExit("bench: %s is %d bytes, above the %d the microbit image takes "
                             "(--cm0-periods)" % (path, os.path.getsize(path), CM0_BLOB_MAX))
        return path

    log("ARMv6-M: recording %d run(s) of %d periods, counting on QEMU microbit" %
        (len(jobs), args.cm0_periods))
    with cf.ThreadPoolExecutor(args.jobs) as ex:
        recs = dict(zip(jobs, ex.map(record, jobs)))
    syms_file = os.path.join(args.work, "syms_cm0.txt")
    _, marks = symbols_file(t["elf"], syms_file)

    def count(job):
        c = qemu_count(t, syms_file, marks, recs[job],
                       os.path.join(args.work, "count_cm0_%s_%d.txt" % job))
        if int(c["summary"].get("differs", -1)) != 0:
            raise SystemExit("bench: ARMv6-M replay of %s at %d r/min differs from the "
                             "recording" % job)
        return job, c

    with cf.ThreadPoolExecutor(args.jobs) as ex:
        cnt = dict(ex.map(count, jobs))
    res = {}
    for n in names:
        run_v = [v for s in speeds for v in cnt[(n, s)]["sections"]["run"]]
        if not run_v:
            continue
        cyc = [c for s in speeds for c in cnt[(n, s)]["cycles"]["run"]]
        est = [v for s in speeds for v in cnt[(n, s)]["sections"]["est"]]
        stp = [v for s in speeds for v in cnt[(n, s)]["sections"]["step"]]
        res[n] = {"cm0_instr_mean": round(statistics.fmean(run_v), 1),
                  "cm0_instr_max": max(run_v),
                  "cm0_est_mean": round(statistics.fmean(est), 1) if est else None,
                  "cm0_step_mean": round(statistics.fmean(stp), 1) if stp else None,
                  # worst call: cycles with every conditional branch taken (upper
                  # bound) and with none taken (lower bound)
                  "cm0p_cycles_max": max(c for c, _ in cyc),
                  "cm0p_cycles_max_lo": max(c - b for c, b in cyc),
                  "cm0p_cycles_mean": round(statistics.fmean(c - b / 2 for c, b in cyc), 1),
                  "cm0_periods": len(run_v)}
    return res


def cm0_fit(cm0):
    """Does CM0_FIT's controller fit its period on the Cortex-M0+? The worst
    call's cycle range against f_cpu / f_pwm."""
    r = cm0.get(CM0_FIT["ctrl"])
    if r is None:
        return None
    budget = CM0_FIT["f_cpu_hz"] // CM0_FIT["f_pwm_hz"]
    lo, hi = r["cm0p_cycles_max_lo"], r["cm0p_cycles_max"]
    fits = True if hi <= budget else (False if lo > budget else None)
    verdict = {True: "fits", False: "does not fit", None: "undecided (range spans the budget)"}
    text = ("%s on a %d MHz Cortex-M0+ at %d kHz: worst fw_isr %d-%d cycles (%d ARMv6-M "
            "instructions) against %d per period (%.0f-%.0f %%): %s" %
            (CM0_FIT["ctrl"], CM0_FIT["f_cpu_hz"] // 1000000, CM0_FIT["f_pwm_hz"] // 1000,
             lo, hi, r["cm0_instr_max"], budget, 100.0 * lo / budget, 100.0 * hi / budget,
             verdict[fits]))
    return dict(CM0_FIT, budget_cycles=budget, worst_cycles=[lo, hi], fits=fits, text=text)


def hotspots(tools, syms, syms_file, marks, recs, name, speeds, work):
    """Per source line (innermost inlined location) and per function: the
    Cortex-M4 instructions per running-period fw_isr call."""
    pcs, calls = {}, 0
    for s in speeds:
        c = qemu_count(tools, syms_file, marks, recs[(name, s)],
                       os.path.join(work, "pcs_%s_%d.txt" % (name, s)), pcsec=2)
        calls += len(c["sections"]["run"])
        for a, v in c["pcs"].items():
            pcs[a] = pcs.get(a, 0) + v
    addrs = sorted(pcs)
    out = run(["arm-none-eabi-addr2line", "-e", tools["elf"], "-f", "-i", "-a"] +
              ["%x" % a for a in addrs])
    # -a prints the address, then (function, file:line) pairs, innermost first.
    frames, cur = {}, None
    for l in out.splitlines():
        if l.startswith("0x"):
            cur = int(l, 16)
            frames[cur] = []
        elif cur is not None:
            fr = frames[cur]
            if fr and len(fr[-1]) == 1:
                loc = re.sub(r" \(discriminator \d+\)", "", l.strip().replace(ROOT + "/", ""))
                loc = re.sub(r"^.*/libgcc/", "libgcc/", loc)
                fr[-1].append(loc)
            else:
                fr.append([l.strip()])
    lines, clines = {}, {}
    for a, fr in frames.items():
        fr = [f for f in fr if len(f) == 2] or [["?", "?"]]
        key = tuple(fr[0])
        lines[key] = lines.get(key, 0) + pcs[a]
        # The innermost frame in a .c file: the line of the calling code that
        # an inlined helper (fx.h, ...) works for.
        ck = tuple(next((f for f in fr if ".c:" in f[1]), fr[0]))
        clines[ck] = clines.get(ck, 0) + pcs[a]
    by_sym = {}
    for a, v in pcs.items():
        nm = next((n for n, (st, sz) in syms.items() if st <= a < st + sz), "?")
        by_sym[nm] = by_sym.get(nm, 0) + v
    calls = max(calls, 1)
    return ({"calls": calls,
             "functions": [[n, round(v / calls, 1)] for n, v in
                           sorted(by_sym.items(), key=lambda kv: -kv[1])],
             "lines": [[fn, loc, round(v / calls, 1)] for (fn, loc), v in
                       sorted(lines.items(), key=lambda kv: -kv[1])],
             "c_lines": [[fn, loc, round(v / calls, 1)] for (fn, loc), v in
                         sorted(clines.items(), key=lambda kv: -kv[1])]})


def stats(v):
    return {"mean": round(statistics.fmean(v), 1), "max": max(v), "min": min(v), "n": len(v)}


def main():
    ap = argparse.ArgumentParser(prog="bench", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench.json"))
    ap.add_argument("--host-build", default=os.environ.get(
        "BENCH_HOST_BUILD", os.path.join(ROOT, "build", "host-release")))
    ap.add_argument("--cm4-build", default=os.environ.get(
        "BENCH_CM4_BUILD", os.path.join(ROOT, "build", "cm4")))
    ap.add_argument("--host-bin", default=None,
                    help="directory with already built bench_rec and bench_host (no host build)")
    ap.add_argument("--work", default=None, help="scratch directory (default out/bench/)")
    ap.add_argument("--periods", type=whole_in(1, 1000000, "periods"), default=2000,
                    help="running periods per recording")
    ap.add_argument("--reps", type=whole_in(1, 10000, "repetitions"), default=31,
                    help="host timing repetitions")
    ap.add_argument("--ctrl", default=None, help="comma-separated subset (default: all)")
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--quick", action="store_true",
                    help="determinism self-test only (one controller, twice; no table)")
    ap.add_argument("--sensorless", action="store_true",
                    help="the firmware without its encoder (fw_config_t.sensorless): recorded at "
                         "5 %% of rated speed (the forced start's final speed), so that the forced "
                         "start, the handover (about 1100 periods) and the observer are counted")
    ap.add_argument("--hfi", action="store_true",
                    help="sensorless with the high-frequency injection (fw_config_t.hfi): recorded "
                         "at 0 r/min on --machine (a salient one whose saturation tells the "
                         "polarity on the dynamometer: thesis_ipmsm_80kw_magsat.ini), --torque; "
                         "the start (angle, tracking's settling, saturation pulses) and the "
                         "tracking are counted")
    ap.add_argument("--torque", type=number_in(float, -1e5, 1e5, "N*m"), default=TORQUE_NM,
                    help="torque reference of the recordings, N*m (default %g)" % TORQUE_NM)
    ap.add_argument("--jobs", type=whole_in(1, 1024, "jobs at once"), default=2)
    ap.add_argument("--cm0-build", default=os.environ.get(
        "BENCH_CM0_BUILD", os.path.join(ROOT, "build", "cm0")))
    ap.add_argument("--cm0-periods", type=whole_in(1, 1700, "periods"), default=1000,
                    help="running periods per ARMv6-M recording (its flash holds about 1700)")
    ap.add_argument("--no-cm0", dest="cm0", action="store_false",
                    help="no ARMv6-M (QEMU microbit) counts")
    ap.add_argument("--machine", default=os.path.join(ROOT, "sim_host", "machines",
                                                       "thesis_spmsm.ini"),
                    help="machine file of the recordings (default: the thesis SPMSM; one with "
                         "[inverter] dead_time_ns counts the dead-time compensation too)")
    ap.add_argument("--hotspots", default="m2ptfc,m1",
                    help="controllers with a per-source-line profile (empty: none)")
    args = ap.parse_args()
    args.work = args.work or os.path.join(os.path.dirname(args.out), "bench")
    os.makedirs(args.work, exist_ok=True)
    t_start = time.time()
    tools = build(args)
    machine = os.path.abspath(args.machine)
    names = run([tools["rec"], "list"]).split()
    if args.ctrl:
        want = args.ctrl.split(",")
        bad = [n for n in want if n not in names]
        if bad:
            ap.error("--ctrl: unknown %s (allowed: %s)" % (",".join(bad), ",".join(names)))
        names = want
    if args.quick:
        names = names if args.ctrl else ["m2ptfc"]
        speeds = (750,)
    else:
        speeds = SPEEDS
    if args.sensorless:
        speeds = (SENSORLESS_RPM,)
    if args.hfi:
        speeds = (0,)
    recdir = os.path.join(args.work, "rec")
    os.makedirs(recdir, exist_ok=True)
    log("recording %d controller(s) x %s r/min, %g N*m, %d running periods" %
        (len(names), "/".join(map(str, speeds)), args.torque, args.periods))

    def record(job):
        n, s = job
        run([tools["rec"], "record", "--machine", machine, "--speed", str(s), "--torque",
             str(args.torque), "--periods", str(args.periods), "--outdir", recdir, "--ctrl", n,
             "--sensorless", "2" if args.hfi else ("1" if args.sensorless else "0")])

    jobs = [(n, s) for n in names for s in speeds]
    with cf.ThreadPoolExecutor(args.jobs) as ex:
        list(ex.map(record, jobs))
    recs = {(n, s): os.path.join(recdir, "%s_%d.bin" % (n, s)) for n, s in jobs}

    # --- Cortex-M4 instruction counts (QEMU + plugin) ---
    syms_file = os.path.join(args.work, "syms.txt")
    syms, marks = symbols_file(tools["elf"], syms_file)
    log("counting Cortex-M4 instructions in QEMU (%d runs)" % len(jobs))

    def count(job):
        n, s = job
        return job, qemu_count(tools, syms_file, marks, recs[job],
                               os.path.join(args.work, "count_%s_%d.txt" % job))

    with cf.ThreadPoolExecutor(args.jobs) as ex:
        cm4 = dict(ex.map(count, jobs))
    # Determinism: the first controller again, every count identical.
    det_job = jobs[0]
    again = qemu_count(tools, syms_file, marks, recs[det_job],
                       os.path.join(args.work, "count_repeat.txt"))
    deterministic = again["raw"] == cm4[det_job]["raw"]
    if not deterministic:
        raise SystemExit("bench: QEMU counts differ between two identical runs")
    log("determinism: %s at %d r/min counted twice, %d calls identical" %
        (det_job[0], det_job[1], len(again["raw"]["run"])))
    if args.quick:
        v = cm4[det_job]["sections"]["run"]
        if not v:
            raise SystemExit("bench: %s: no running period in the recording" % det_job[0])
        print("bench quick: %s %d r/min: fw_isr mean %.1f max %d instructions over %d calls; "
              "repeat identical: %s" % (det_job[0], det_job[1], statistics.fmean(v), max(v),
                                        len(v), deterministic))
        if not (min(v) > 100 and max(v) < 20000):
            raise SystemExit("bench: implausible count")
        if args.cm0:
            r = cm0_counts(args, tools, [det_job[0]], speeds, machine).get(det_job[0])
            if r is None:
                raise SystemExit("bench: %s: no running period on ARMv6-M" % det_job[0])
            print("bench quick: ARMv6-M (QEMU microbit) %s %d r/min: fw_isr mean %.1f max %d "
                  "instructions over %d calls, replay identical to the recording; worst call "
                  "%d-%d Cortex-M0+ cycles" % (det_job[0], det_job[1], r["cm0_instr_mean"],
                                               r["cm0_instr_max"], r["cm0_periods"],
                                               r["cm0p_cycles_max_lo"], r["cm0p_cycles_max"]))
            # every instruction takes at least one cycle; the bound with every
            # branch taken is not below the one with none taken
            if not (100 < r["cm0_instr_max"] < 100000 and
                    r["cm0_instr_max"] <= r["cm0p_cycles_max_lo"] <= r["cm0p_cycles_max"]):
                raise SystemExit("bench: implausible ARMv6-M count")
        return 0

    failed = [n for n in names if any(not cm4[(n, s)]["sections"]["run"] for s in speeds)]
    for n in failed:
        log("%s: no running period in a recording (the drive faulted at once): no row" % n)
    names = [n for n in names if n not in failed]
    jobs = [(n, s) for n, s in jobs if n not in failed]
    hot = {}
    for n in [h for h in args.hotspots.split(",") if h in names]:
        log("per-line profile of %s" % n)
        hot[n] = hotspots(tools, syms, syms_file, marks, recs, n, speeds, args.work)

    # --- PC: wall time (interleaved repetitions) and callgrind ---
    log("timing on the PC (%d repetitions)" % args.reps)
    host_t = {}
    out = run([tools["host"], "time", "--reps", str(args.reps)] + [recs[j] for j in jobs])
    for line in out.splitlines():
        d = json.loads(line)
        host_t[(d["ctrl"], d["speed_rpm"])] = d
    host_instr = {}
    if not args.no_callgrind and shutil.which("valgrind"):
        log("callgrind on the PC (%d runs)" % len(names))

        def cg(n):
            cgo = os.path.join(args.work, "callgrind_%s.out" % n)
            r = subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=bench_isr_running",
                                "--callgrind-out-file=" + cgo, tools["host"], "replay"] +
                               [recs[(n, s)] for s in speeds],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if r.returncode != 0:
                raise SystemExit("bench: callgrind failed for %s: %s" % (n, r.stderr[-2000:]))
            calls = sum(json.loads(l)["calls"] for l in r.stdout.splitlines())
            ir = None
            with open(cgo) as f:
                for l in f:
                    if l.startswith("totals:") or l.startswith("summary:"):
                        ir = int(l.split()[1])
            return n, round(ir / calls, 1)

        with cf.ThreadPoolExecutor(args.jobs) as ex:
            host_instr = dict(ex.map(cg, names))

    cm0 = cm0_counts(args, tools, names, speeds, machine) if args.cm0 else {}

    # --- footprint ---
    sizes = {}
    for n in ["none"] + names:
        elf = os.path.join(tools["cdir"], "bench_size_%s.elf" % n)
        t, d, b = map(int, run(["arm-none-eabi-size", elf]).splitlines()[1].split()[:3])
        sizes[n] = (t + d, d + b)

    # --- results ---
    res = {}
    for n in names:
        allv = [v for s in speeds for v in cm4[(n, s)]["sections"]["run"]]
        r = {"cm4_instr_mean": round(statistics.fmean(allv), 1), "cm4_instr_max": max(allv)}
        for s in speeds:
            c = cm4[(n, s)]
            r["cm4_%d" % s] = stats(c["sections"]["run"]) if c["sections"]["run"] else None
            r["cm4_est_%d" % s] = stats(c["sections"]["est"]) if c["sections"]["est"] else None
            r["cm4_step_%d" % s] = stats(c["sections"]["step"]) if c["sections"]["step"] else None
            r["cm4_boot_%d" % s] = stats(c["sections"]["boot"])
            calls = max(1, len(c["sections"]["run"]))
            prof = sorted(c["profile"]["run"].items(), key=lambda kv: -kv[1][0])
            r["cm4_profile_%d" % s] = [[f, round(v / calls, 1), round(e / calls, 2)]
                                       for f, (v, e) in prof[:20]]
            r["replay_differs_%d" % s] = int(c["summary"].get("differs", -1))
            r["running_periods_%d" % s] = calls
            r["not_running_periods_%d" % s] = int(c["summary"].get("not_running", -1))
            r["host_ns_median_%d" % s] = host_t[(n, s)]["ns_median"]
        est = [v for s in speeds for v in cm4[(n, s)]["sections"]["est"]]
        stp = [v for s in speeds for v in cm4[(n, s)]["sections"]["step"]]
        r["cm4_est_mean"] = round(statistics.fmean(est), 1) if est else None
        r["cm4_step_mean"] = round(statistics.fmean(stp), 1) if stp else None
        r["cm4_step_max"] = max(stp) if stp else None
        # the medium-rate task (fw_medium): its runs, and its instructions
        # spread over the PWM periods (of the whole recording: boot included)
        mid = [v for s in speeds for v in cm4[(n, s)]["sections"]["mid"]]
        periods = sum(len(cm4[(n, s)]["sections"][k]) for s in speeds for k in ("run", "boot"))
        r["cm4_mid_mean"] = round(statistics.fmean(mid), 1) if mid else None
        r["cm4_mid_max"] = max(mid) if mid else None
        r["mid_runs"] = len(mid)
        r["cm4_mid_per_period"] = round(sum(mid) / periods, 1) if periods else None
        r["host_ns_median"] = round(statistics.fmean(host_t[(n, s)]["ns_median"]
                                                      for s in speeds), 1)
        r["host_instr"] = host_instr.get(n)
        r["flash_bytes"] = sizes[n][0] - sizes["none"][0]
        r["ram_bytes"] = sizes[n][1] - sizes["none"][1]
        r["state_bytes"] = int(cm4[(n, speeds[0])]["summary"].get("state_bytes", 0))
        r["fs_hz"] = int(cm4[(n, speeds[0])]["summary"].get("fs", 0))
        r.update(cm0.get(n, {}))
        res[n] = r
    ref = "m1" if "m1" in res else names[0]
    for n in names:
        res[n]["host_ratio_to_m1"] = round(res[n]["host_ns_median"] / res[ref]["host_ns_median"], 3)
        res[n]["cm4_ratio_to_m1"] = round(res[n]["cm4_instr_mean"] / res[ref]["cm4_instr_mean"], 3)
    doc = {
        "method": {
            "scenario": "%s, dynamometer at %s r/min, torque reference %g N*m, "
                        "controller default fs, %d running periods after arm (plus boot and "
                        "calibration, not counted)%s" % (
                            os.path.basename(machine), "/".join(map(str, speeds)), args.torque,
                            args.periods,
                            "; sensorless with the injection" if args.hfi else
                            ("; sensorless" if args.sensorless else "")),
            "cm4": "QEMU mps2-an386 (Cortex-M4F, -O2 -g), recorded inputs replayed through "
                   "fw_isr_fast (the PWM-period interrupt) and, where it triggered one, "
                   "fw_medium (the medium-rate task), counted apart; exact instruction counts "
                   "between marker calls from a TCG plugin (tools/bench_fw/bench_plugin.c), "
                   "marker overhead subtracted; counts include the call (argument set-up and "
                   "bl)",
            "host": "host-release -O2, median over repetitions of the mean wall time per "
                    "running-period ISR (CLOCK_MONOTONIC), averaged over the two speeds",
            "host_instr": "valgrind --tool=callgrind --toggle-collect=bench_isr_running: "
                          "instructions per running-period fw_isr call",
            "footprint": "arm-none-eabi-size of a minimal cm4 image (pipeline + replay HAL) "
                         "whose registry holds only this controller, minus the same image with "
                         "an empty registry; flash = text + data, ram = data + bss; "
                         "state_bytes = desc->state_size (lives in fw_t's fixed block)",
            "cm0": "QEMU microbit (Cortex-M0, ARMv6-M = the Cortex-M0+'s instruction set), "
                   "image bench_cm0 built with the cm0 preset's flags (-mcpu=cortex-m0plus "
                   "-O2 -g), %d-period recordings replayed through fw_isr, checked period by "
                   "period; cm0_instr_*: instructions per running-period call; cm0p_cycles_*: "
                   "Cortex-M0+ cycles from the plugin's per-instruction weights (ARM DDI 0484C "
                   "Table 3-1, zero-wait-state memory, single-cycle multiplier; max: worst call "
                   "with every conditional branch taken, max_lo: with none taken; mean: "
                   "half taken); exception entry and exit (about 30 cycles) not included"
                   % args.cm0_periods,
        },
        "deterministic": deterministic,
        "thesis_us": THESIS_US,
        "baseline_image": {"flash_bytes": sizes["none"][0], "ram_bytes": sizes["none"][1]},
        "wall_s": round(time.time() - t_start, 1),
        "controllers": res,
        "failed": failed,
        "hotspots": hot,
        "cm0_fit": cm0_fit(cm0) if cm0 else None,
    }
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(doc, f, indent=1)
    print_table(doc, names, ref, args.out)
    return 0


def print_table(doc, names, ref, out_path):
    c = doc["controllers"]
    hdr = ("%-10s %9s %7s %8s %8s %8s %8s %7s %7s %6s %8s %6s %9s %7s %6s %6s %8s %6s" %
           ("controller", "cm4 mean", "max", "@750", "@2250", "est", "step", "mid", "max",
            "/T", "host ns", "/m1", "host ins", "flash", "ram", "state", "m0 mean", "max"))
    print(hdr)
    print("-" * len(hdr))
    for n in names:
        r = c[n]
        m750 = (r.get("cm4_750") or {}).get("mean", float("nan"))
        m2250 = (r.get("cm4_2250") or {}).get("mean", float("nan"))
        flag = "*" if any(r.get("not_running_periods_%d" % s, 0) for s in SPEEDS) else ""
        hi = r["host_instr"]
        print("%-10s %9.1f %7d %8.1f %8.1f %8s %8s %7s %7s %6s %8.1f %6.2f %9s %7d %6d %6d %8s %6s" %
              (n + flag, r["cm4_instr_mean"], r["cm4_instr_max"], m750, m2250,
               "%.1f" % r["cm4_est_mean"] if r["cm4_est_mean"] is not None else "-",
               "%.1f" % r["cm4_step_mean"] if r["cm4_step_mean"] is not None else "-",
               "%.1f" % r["cm4_mid_mean"] if r["cm4_mid_mean"] is not None else "-",
               r["cm4_mid_max"] if r["cm4_mid_max"] is not None else "-",
               "%.1f" % r["cm4_mid_per_period"] if r["cm4_mid_per_period"] is not None else "-",
               r["host_ns_median"], r["host_ratio_to_m1"],
               "%.1f" % hi if hi is not None else "-", r["flash_bytes"], r["ram_bytes"],
               r["state_bytes"], "%.1f" % r["cm0_instr_mean"] if "cm0_instr_mean" in r else "-",
               r.get("cm0_instr_max", "-")))
    print()
    print("cm4: Cortex-M4 instructions per fw_isr_fast call, the PWM-period interrupt (QEMU, "
          "exact, deterministic: %s); est/step: estimator / controller step alone (mean); "
          "mid/max: the medium-rate task fw_medium per run (mean, max); /T: its instructions "
          "per PWM period; host ns: median wall time per period, both rates "
          "(-O2, this PC); /m1: host ratio to %s; host ins: callgrind instructions per "
          "period; flash/ram: bytes added to a cm4 image; state: controller state bytes; "
          "m0: ARMv6-M instructions per fw_isr call (QEMU microbit, shorter recordings)."
          % (doc["deterministic"], ref))
    if doc.get("cm0_fit"):
        print(doc["cm0_fit"]["text"])
    faulted = ["%s@%d" % (n, s) for n in names for s in SPEEDS
               if c[n].get("not_running_periods_%d" % s, 0)]
    if faulted:
        print("* the drive faulted during the recording (%s): only the running periods before "
              "the fault are counted" % ", ".join(faulted))
    th = doc["thesis_us"]
    if all(k in c for k in th):
        print("thesis (dSPACE DS1202) vs here, ratio to m1:  " + ", ".join(
            "%s %.2f | cm4 %.2f, host %.2f" % (k, th[k] / th["m1"],
                                                c[k]["cm4_instr_mean"] / c["m1"]["cm4_instr_mean"],
                                                c[k]["host_ns_median"] / c["m1"]["host_ns_median"])
            for k in ("m2ptfc", "m2", "m3")))
    rel = os.path.relpath(out_path, ROOT)
    print("written: %s (wall %.0f s)" % (out_path if rel.startswith("..") else rel, doc["wall_s"]))


if __name__ == "__main__":
    sys.exit(main())
