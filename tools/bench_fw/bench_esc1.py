#!/usr/bin/python3
"""Instructions of the B-G431B-ESC1's control interrupt, and what they mean at 170 MHz.

    tools/bench --esc1 [--ctrl a,b] [--periods N] [--fs HZ] [--sensorless]
                       [--out FILE]

The bench's method (tools/bench, README "Interrupt cost"): a host closed loop
(thesis SPMSM on a dynamometer, 750 r/min, 1.8 N*m) is recorded and replayed
on the emulated Cortex-M4 with the counting plugin. Here the replayed code is
the board image's control interrupt, esc1_control_isr (flags acknowledged,
fw_isr_fast with the G4 back-end of hal.h reading the ADC data registers, the
encoder counter and writing TIM1_CCRx, PendSV pended when the medium-rate
task is due), and that task (fw_medium, PendSV's handler), counted apart;
built with the cm4 toolchain
and link-time optimisation, as the image is (build/cm4-lto), as
esc1_isr_bench with the peripheral registers in arrays (the same
instructions as at the chip's addresses). Every period's compare values must
equal the recording. For comparison the same recording through bench_cm4
(fw_isr_fast with the replay HAL). --fs records at another PWM frequency
(default: the controller's), --sensorless without the encoder (at 5 % of
rated speed, so that the forced start, the handover and the observer are
counted; tools/bench --sensorless).

Time at 170 MHz: instructions x CPI / 170 MHz, with CPI between 1.0 (every
instruction one cycle) and 1.5 (loads, taken branches, divisions; flash wait
states hidden by the ART accelerator's prefetch and cache); plus the
exception entry and exit (12 + 12 cycles without FP context, up to 2 x 29
with lazy FP stacking) that no instruction count sees.
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench  # noqa: E402  (same folder: configure, run, symbols, qemu_count)

ROOT = bench.ROOT
F_CPU = 170e6
ENTRY_EXIT_CYCLES = (24, 58)


def board_core_options():
    """The b-g431b-esc1 preset's options of the control core and firmware
    (PMSM_* except the target, board and machine-file choices)."""
    with open(os.path.join(ROOT, "CMakePresets.json")) as f:
        presets = json.load(f)["configurePresets"]
    board = next(p for p in presets if p["name"] == "b-g431b-esc1")
    skip = {"PMSM_TARGET", "PMSM_BOARD", "PMSM_ESC1_MACHINE_INI", "PMSM_ESC1_SETTINGS"}
    return {k: v for k, v in board.get("cacheVariables", {}).items()
            if k.startswith("PMSM_") and k not in skip}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ctrl", default=",".join(
        board_core_options().get("PMSM_CONTROLLERS", "m2ptfc;foc;fst;drr").split(";")),
                    help="controllers (default: every one the board preset links)")
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--speed", type=int, default=None,
                    help="r/min (default 750; %d with --sensorless)" % bench.SENSORLESS_RPM)
    ap.add_argument("--fs", type=int, default=0, help="PWM frequency, Hz (0: the controller's)")
    ap.add_argument("--sensorless", action="store_true")
    ap.add_argument("--budget", type=float, default=0.60,
                    help="share of the period the interrupt may take at CPI 1.5 (verdict)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench_esc1.json"))
    ap.add_argument("--host-build", default=os.environ.get(
        "BENCH_HOST_BUILD", os.path.join(ROOT, "build", "host-release")))
    ap.add_argument("--cm4-build", default=os.environ.get(
        "BENCH_CM4_BUILD", os.path.join(ROOT, "build", "cm4-lto")))
    args = ap.parse_args()
    if args.speed is None:
        args.speed = bench.SENSORLESS_RPM if args.sensorless else 750
    work = os.path.join(os.path.dirname(args.out), "bench_esc1")
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
    cm4_vars.update(board_core_options())
    bench.configure(cm4, cm4_vars, toolchain=os.path.join(ROOT, "tools", "cmake",
                                                          "arm-none-eabi-cm4.cmake"),
                    update=True)
    bench.log("building bench_rec (host-release), esc1_isr_bench and bench_cm4 (cm4)")
    bench.run(["cmake", "--build", host, "-j2", "--target", "bench_rec"])
    bench.run(["cmake", "--build", cm4, "-j2", "--target", "esc1_isr_bench", "bench_cm4"])
    plugin = os.path.join(work, "bench_plugin.so")
    bench.run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin,
               os.path.join(bench.FW, "bench_plugin.c")])
    rec_bin = os.path.join(host, "tests", "bench", "bench_fw", "bench_rec")
    images = {"esc1": os.path.join(cm4, "tests", "board", "esc1_isr_bench.elf"),
              "replay": os.path.join(cm4, "tests", "bench", "bench_fw", "bench_cm4.elf")}
    machine = os.path.join(ROOT, "sim_host", "machines", "thesis_spmsm.ini")
    recdir = os.path.join(work, "rec")
    os.makedirs(recdir, exist_ok=True)
    names = args.ctrl.split(",")
    result = {"f_cpu_hz": F_CPU, "speed_rpm": args.speed, "torque_nm": bench.TORQUE_NM,
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
            if kind == "esc1" and c["summary"].get("differs") != "0":
                raise SystemExit("bench_esc1: %s: the board path computed other compare values "
                                 "than the recording: %s" % (n, c["summary"]))
            # qemu_count names the sections by position (bench.SECTIONS); an
            # image without some markers (esc1: no est/step) shifts them
            names = [m[len("bench_mark_end_"):] for m in markers[1:]]
            sec = {names[i]: c["sections"].get(bench.SECTIONS[i], [])
                   for i in range(1, len(names))}
            counts[kind] = sec["run"]
            if kind == "esc1":
                mid = sec.get("mid", [])
                periods = len(sec["run"]) + len(sec["boot"])
        v = counts["esc1"]
        if not v:
            raise SystemExit("bench_esc1: %s: no running period" % n)
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
             "us_at_170mhz_max": us_entry, "share_of_period": [u / period_us for u in us_entry],
             "recording_fs_hz": fs, "mid_instr_mean": mid_mean, "mid_instr_max": mid_max,
             "mid_runs": len(mid), "mid_instr_per_period": sum(mid) / periods if periods else 0,
             "within_budget_at_cpi_1_5": us_entry[1] / period_us <= args.budget}
        result["controllers"][n] = d
        rows.append((n, mean, mx, d["replay_hal_instr_mean"], us_entry, period_us, d))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print("B-G431B-ESC1 control interrupt (esc1_control_isr), Cortex-M4 instructions in QEMU,")
    print("%d running periods at %d r/min, %.1f N*m%s; time at 170 MHz for CPI 1.0 .. 1.5 incl. "
          "exception entry/exit; share of the PWM period" %
          (args.periods, args.speed, bench.TORQUE_NM, ", sensorless" if args.sensorless else ""))
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
    print("written: " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
