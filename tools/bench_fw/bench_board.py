#!/usr/bin/python3
"""Instructions of a board image's control interrupt, and what they mean at its clock.

    tools/bench --esc1 [--ctrl a,b] [--periods N] [--fs HZ] [--sensorless]
                       [--out FILE]
    tools/bench --board vesc6|odrive-v36 [the same options]

The bench's method (tools/bench, docs/bench.md): a host closed loop
(thesis SPMSM on a dynamometer, 750 r/min, 1.8 N*m) is recorded and replayed
on the emulated Cortex-M4 with the counting plugin. Here the replayed code is
the board image's control interrupt (esc1_control_isr with the G4 back-end
of hal.h for the B-G431B-ESC1; f405_control_isr with the F4 back-end set up
for the board by f4_hal_describe for the VESC 6 and the ODrive v3.6): flags
acknowledged, fw_isr_fast reading the ADC data registers and the encoder
counter and writing TIM1_CCRx, PendSV pended when the medium-rate task is
due; and that task (fw_medium, PendSV's handler), counted apart; built with
the cm4 toolchain and link-time optimisation, as the image is, with the
core's options of the board's preset (build/cm4-lto for the ESC1,
build/cm4-lto-f405 for the F405 boards), as <board>_isr_bench with the
peripheral registers in arrays (the same instructions as at the chip's
addresses). Every period's compare values must equal the recording. For
comparison the same recording through bench_cm4 (fw_isr_fast with the replay
HAL). --fs records at another PWM frequency (default: the controller's),
--sensorless without the encoder (at 5 % of rated speed, so that the forced
start, the handover and the observer are counted; tools/bench --sensorless).

Time at the board's clock (170 MHz G431, 168 MHz F405): instructions x CPI /
f_CPU, with CPI between 1.0 (every instruction one cycle) and 1.5 (loads,
taken branches, divisions; flash wait states hidden by the prefetch and the
instruction cache: ART on both parts); plus the exception entry and exit
(12 + 12 cycles without FP context, up to 2 x 29 with lazy FP stacking)
that no instruction count sees. The F405 boards' table gives that worst case
as a share of a 20, 30 and 40 kHz period (8400, 5600, 4200 cycles).
"""

import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench  # noqa: E402  (same folder: configure, run, symbols, qemu_count)

ROOT = bench.ROOT
ENTRY_EXIT_CYCLES = (24, 58)
# preset: its image's bench target, core clock, the cm4 build it is counted in,
# the name of its output, the PWM frequencies whose period shares are listed
BOARDS = {
    "b-g431b-esc1": {"target": "esc1_isr_bench", "f_cpu": 170e6, "build": "cm4-lto",
                     "out": "bench_esc1", "name": "B-G431B-ESC1", "isr": "esc1_control_isr",
                     "shares": ()},
    "vesc6": {"target": "f405_isr_bench_vesc6", "f_cpu": 168e6, "build": "cm4-lto-f405",
              "out": "bench_vesc6", "name": "VESC 6", "isr": "f405_control_isr",
              "shares": (20000, 30000, 40000)},
    "odrive-v36": {"target": "f405_isr_bench_odrive_v36", "f_cpu": 168e6,
                   "build": "cm4-lto-f405", "out": "bench_odrive_v36", "name": "ODrive v3.6",
                   "isr": "f405_control_isr", "shares": (20000, 30000, 40000)},
}


def board_core_options(preset):
    """A board preset's options of the control core and firmware (PMSM_*
    except the target, board and machine-file choices)."""
    with open(os.path.join(ROOT, "CMakePresets.json")) as f:
        presets = json.load(f)["configurePresets"]
    board = next(p for p in presets if p["name"] == preset)
    skip = {"PMSM_TARGET", "PMSM_BOARD", "PMSM_ESC1_MACHINE_INI", "PMSM_ESC1_SETTINGS",
            "PMSM_F405_MACHINE_INI"}
    opts = {k: v for k, v in board.get("cacheVariables", {}).items()
            if k.startswith("PMSM_") and k not in skip}
    # Options whose default follows the target (control/CMakeLists.txt): the
    # bench builds for cm4, so the board's default is given explicitly.
    target = board.get("cacheVariables", {}).get("PMSM_TARGET")
    if target in ("cm0", "stm32g4"):
        opts.setdefault("PMSM_COGGING", "OFF")
    return opts


def registry_all():
    """Every controller of the core (control/CMakeLists.txt, PMSM_CONTROLLERS_ALL)."""
    import re
    text = open(os.path.join(ROOT, "control", "CMakeLists.txt")).read()
    m = re.search(r"set\(PMSM_CONTROLLERS_ALL\b(.*?)\bCACHE\b", text, re.S)
    body = re.sub(r"#[^\n]*", "", m.group(1)) if m else ""
    return body.split()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--board", choices=sorted(BOARDS), default="b-g431b-esc1",
                    help="the board preset whose image is counted (tools/bench --esc1: "
                         "b-g431b-esc1)")
    ap.add_argument("--ctrl", default=None,
                    help="controllers (default: every one the board preset links)")
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--speed", type=int, default=None,
                    help="r/min (default 750; %d with --sensorless)" % bench.SENSORLESS_RPM)
    ap.add_argument("--fs", type=int, default=0, help="PWM frequency, Hz (0: the controller's)")
    ap.add_argument("--sensorless", action="store_true")
    ap.add_argument("--cpi", type=float, default=1.5,
                    help="cycles per instruction of the period-share table (F405 boards)")
    ap.add_argument("--budget", type=float, default=0.60,
                    help="share of the period the interrupt may take at CPI 1.5 (verdict)")
    ap.add_argument("--out", default=None, help="default: out/bench_<board>.json")
    ap.add_argument("--host-build", default=os.environ.get(
        "BENCH_HOST_BUILD", os.path.join(ROOT, "build", "host-release")))
    ap.add_argument("--cm4-build", default=os.environ.get("BENCH_CM4_BUILD"),
                    help="default: build/cm4-lto (ESC1), build/cm4-lto-f405 (F405 boards)")
    args = ap.parse_args()
    B = BOARDS[args.board]
    F_CPU = B["f_cpu"]
    core = board_core_options(args.board)
    if args.ctrl is None:
        args.ctrl = ",".join(core["PMSM_CONTROLLERS"].split(";") if "PMSM_CONTROLLERS" in core
                             else registry_all())
    if args.out is None:
        args.out = os.path.join(ROOT, "out", B["out"] + ".json")
    if args.cm4_build is None:
        args.cm4_build = os.path.join(ROOT, "build", B["build"])
    if args.speed is None:
        args.speed = bench.SENSORLESS_RPM if args.sensorless else 750
    work = os.path.join(os.path.dirname(args.out), B["out"])
    os.makedirs(work, exist_ok=True)
    host, cm4 = args.host_build, args.cm4_build
    bench.configure(host, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2",
                           "CMAKE_CXX_FLAGS_RELEASE": "-O2", "PMSM_TARGET": "host",
                           "PMSM_SANITIZE": "OFF"})
    # With link-time optimisation and the core's options of the board image
    # (its preset in CMakePresets.json: e.g. no dead-time compensation, no
    # sensorless initial angle), so that the count is the image's code.
    cm4_vars = {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2 -g",
                "CMAKE_CXX_FLAGS_RELEASE": "-O2 -g", "PMSM_TARGET": "cm4",
                "CMAKE_INTERPROCEDURAL_OPTIMIZATION": "ON"}
    cm4_vars.update(core)
    bench.configure(cm4, cm4_vars, toolchain=os.path.join(ROOT, "tools", "cmake",
                                                          "arm-none-eabi-cm4.cmake"),
                    update=True)
    bench.log("building bench_rec (host-release), %s and bench_cm4 (cm4)" % B["target"])
    bench.run(["cmake", "--build", host, "-j2", "--target", "bench_rec"])
    bench.run(["cmake", "--build", cm4, "-j2", "--target", B["target"], "bench_cm4"])
    plugin = os.path.join(work, "bench_plugin.so")
    bench.run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin,
               os.path.join(bench.FW, "bench_plugin.c")])
    rec_bin = os.path.join(host, "tests", "bench", "bench_fw", "bench_rec")
    images = {"board": os.path.join(cm4, "tests", "board", B["target"] + ".elf"),
              "replay": os.path.join(cm4, "tests", "bench", "bench_fw", "bench_cm4.elf")}
    machine = os.path.join(ROOT, "sim_host", "machines", "thesis_spmsm.ini")
    recdir = os.path.join(work, "rec")
    os.makedirs(recdir, exist_ok=True)
    names = args.ctrl.split(",")
    us_key = "us_at_%.0fmhz_max" % (F_CPU / 1e6)
    result = {"board": args.board, "f_cpu_hz": F_CPU, "speed_rpm": args.speed,
              "torque_nm": bench.TORQUE_NM,
              "controllers": {}}
    rows = []
    for n in names:
        bench.run([rec_bin, "record", "--machine", machine, "--speed", str(args.speed),
                   "--torque", str(bench.TORQUE_NM), "--periods", str(args.periods),
                   "--outdir", recdir, "--ctrl", n, "--sensorless",
                   "1" if args.sensorless else "0"] +
                  (["--fs", str(args.fs)] if args.fs else []))
        rec = os.path.join(recdir, "%s_%d.bin" % (n, args.speed))
        counts = {}
        for kind, elf in images.items():
            syms = bench.symbols(elf)
            syms_file = os.path.join(work, "syms_%s.txt" % kind)
            with open(syms_file, "w") as f:
                for name, (a, size) in syms.items():
                    f.write("%x %d %s\n" % (a, size, name))
            markers = [m for m in bench.MARKERS if m in syms]
            marks = [syms[m][0] for m in markers]
            tools = {"elf": elf, "plugin": plugin, **bench.CM4_TARGET}
            c = bench.qemu_count(tools, syms_file, marks, rec,
                                 os.path.join(work, "count_%s_%s.txt" % (kind, n)))
            if kind == "board" and c["summary"].get("differs") != "0":
                raise SystemExit("bench %s: %s: the board path computed other compare values "
                                 "than the recording: %s" % (args.board, n, c["summary"]))
            # qemu_count names the sections by position (bench.SECTIONS); an
            # image without some markers (esc1: no est/step) shifts them
            names = [m[len("bench_mark_end_"):] for m in markers[1:]]
            sec = {names[i]: c["sections"].get(bench.SECTIONS[i], [])
                   for i in range(1, len(names))}
            counts[kind] = sec["run"]
            if kind == "board":
                mid = sec.get("mid", [])
                periods = len(sec["run"]) + len(sec["boot"])
        v = counts["board"]
        if not v:
            raise SystemExit("bench %s: %s: no running period" % (args.board, n))
        fs = int(c["summary"].get("fs", "0")) or 20000
        mean, mx = statistics.fmean(v), max(v)
        us = [mx * cpi / F_CPU * 1e6 for cpi in (1.0, 1.5)]
        us_entry = [us[0] + ENTRY_EXIT_CYCLES[0] / F_CPU * 1e6,
                    us[1] + ENTRY_EXIT_CYCLES[1] / F_CPU * 1e6]
        period_us = 1e6 / fs
        mid_mean = statistics.fmean(mid) if mid else 0.0
        mid_max = max(mid) if mid else 0
        d = {"isr_instr_mean": mean, "isr_instr_max": mx, "calls": len(v),
             "replay_hal_instr_mean": statistics.fmean(counts["replay"]),
             us_key: us_entry, "share_of_period": [u / period_us for u in us_entry],
             "recording_fs_hz": fs, "mid_instr_mean": mid_mean, "mid_instr_max": mid_max,
             "mid_runs": len(mid), "mid_instr_per_period": sum(mid) / periods if periods else 0,
             "within_budget_at_cpi_1_5": us_entry[1] / period_us <= args.budget}
        result["controllers"][n] = d
        rows.append((n, mean, mx, d["replay_hal_instr_mean"], us_entry, period_us, d))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print("%s control interrupt (%s), Cortex-M4 instructions in QEMU," % (B["name"], B["isr"]))
    print("%d running periods at %d r/min, %.1f N*m%s; time at %.0f MHz for CPI 1.0 .. 1.5 incl. "
          "exception entry/exit; share of the PWM period" %
          (args.periods, args.speed, bench.TORQUE_NM, ", sensorless" if args.sensorless else "",
           F_CPU / 1e6))
    print("%-8s %6s %8s %6s %11s %16s %14s %8s %6s %6s %7s" %
          ("ctrl", "fs", "mean", "max", "replay-HAL", "us (max)", "% of period", "<=%d%%" %
           round(100 * args.budget), "mid", "max", "mid/T"))
    for n, mean, mx, rep, us, per, d in rows:
        print("%-8s %6d %8.1f %6d %11.1f %7.2f .. %5.2f %6.1f .. %5.1f %8s %6.1f %6d %7.1f" %
              (n, d["recording_fs_hz"], mean, mx, rep, us[0], us[1], 100 * us[0] / per,
               100 * us[1] / per, "yes" if d["within_budget_at_cpi_1_5"] else "NO",
               d["mid_instr_mean"], d["mid_instr_max"], d["mid_instr_per_period"]))
    print("(mean, max: the interrupt's instructions; replay-HAL: the same periods through "
          "bench_cm4's fw_isr_fast with the replay HAL; mid, max: the medium-rate task per run, "
          "mid/T: its instructions per PWM period; <=: the interrupt's worst case at CPI 1.5 "
          "within that share of the period)")
    if B["shares"]:
        cpi = args.cpi
        print()
        print("worst case at CPI %.2f incl. entry/exit (%d cycles) as a share of the period at "
              "%.0f MHz:" % (cpi, ENTRY_EXIT_CYCLES[1] if cpi > 1.0 else ENTRY_EXIT_CYCLES[0],
                             F_CPU / 1e6))
        print("%-8s %8s" % ("ctrl", "cycles") + "".join(
            "  %8.0f kHz" % (f / 1e3) for f in B["shares"]) + "  (+ mid/T at each)")
        for n, mean, mx, rep, us, per, d in rows:
            cyc = mx * cpi + (ENTRY_EXIT_CYCLES[1] if cpi > 1.0 else ENTRY_EXIT_CYCLES[0])
            shares = [cyc / (F_CPU / f) for f in B["shares"]]
            with_mid = [(cyc + d["mid_instr_per_period"] * cpi) / (F_CPU / f) for f in B["shares"]]
            d["cycles_worst_at_cpi"] = cyc
            d["share_at"] = {str(f): sh for f, sh in zip(B["shares"], shares)}
            print("%-8s %8.0f" % (n, cyc) + "".join(
                "  %10.1f %%" % (100 * x) for x in shares) + "  (" + ", ".join(
                "%.1f %%" % (100 * x) for x in with_mid) + ")")
        print("(the period: %s cycles; the medium-rate task runs in PendSV between periods)" %
              ", ".join("%.0f" % (F_CPU / f) for f in B["shares"]))
        with open(args.out, "w") as f:
            json.dump(result, f, indent=1)
    print("written: " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
