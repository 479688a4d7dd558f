#!/usr/bin/python3
"""Instructions of the B-G431B-ESC1's control interrupt, and what they mean at 170 MHz.

    tools/bench --esc1 [--ctrl m2ptfc,foc,fst,drr] [--periods N] [--out FILE]

The bench's method (tools/bench, README "Interrupt cost"): a host closed loop
(thesis SPMSM on a dynamometer, 750 r/min, 1.8 N*m) is recorded and replayed
on the emulated Cortex-M4 with the counting plugin. Here the replayed code is
the board image's control interrupt, esc1_control_isr (flags acknowledged,
fw_isr with the G4 back-end of hal.h reading the ADC data registers, the
encoder counter and writing TIM1_CCRx, fw_link_isr), built by the cm4 preset
as esc1_isr_bench with the peripheral registers in arrays (the same
instructions as at the chip's addresses). Every period's compare values must
equal the recording. For comparison the same recording through bench_cm4
(fw_isr with the replay HAL).

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


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ctrl", default="m2ptfc,foc,fst,drr")
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--speed", type=int, default=750)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench_esc1.json"))
    ap.add_argument("--host-build", default=os.environ.get(
        "BENCH_HOST_BUILD", os.path.join(ROOT, "build", "host-release")))
    ap.add_argument("--cm4-build", default=os.environ.get(
        "BENCH_CM4_BUILD", os.path.join(ROOT, "build", "cm4")))
    args = ap.parse_args()
    work = os.path.join(os.path.dirname(args.out), "bench_esc1")
    os.makedirs(work, exist_ok=True)
    host, cm4 = args.host_build, args.cm4_build
    bench.configure(host, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2",
                           "CMAKE_CXX_FLAGS_RELEASE": "-O2", "PMSM_TARGET": "host",
                           "PMSM_SANITIZE": "OFF"})
    bench.configure(cm4, {"CMAKE_BUILD_TYPE": "Release", "CMAKE_C_FLAGS_RELEASE": "-O2 -g",
                          "CMAKE_CXX_FLAGS_RELEASE": "-O2 -g", "PMSM_TARGET": "cm4"},
                    toolchain=os.path.join(ROOT, "tools", "cmake", "arm-none-eabi-cm4.cmake"))
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
                   "--outdir", recdir, "--ctrl", n])
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
            counts[kind] = c["sections"]["run"]
        v = counts["esc1"]
        if not v:
            raise SystemExit("bench_esc1: %s: no running period" % n)
        fs = int(c["summary"].get("fs", "0")) or 20000
        mean, mx = statistics.fmean(v), max(v)
        us = [mx * cpi / F_CPU * 1e6 for cpi in (1.0, 1.5)]
        us_entry = [us[0] + ENTRY_EXIT_CYCLES[0] / F_CPU * 1e6,
                    us[1] + ENTRY_EXIT_CYCLES[1] / F_CPU * 1e6]
        period_us = 1e6 / 20000.0
        d = {"isr_instr_mean": mean, "isr_instr_max": mx, "calls": len(v),
             "replay_hal_instr_mean": statistics.fmean(counts["replay"]),
             "us_at_170mhz_max": us_entry, "share_of_50us": [u / period_us for u in us_entry],
             "recording_fs_hz": fs}
        result["controllers"][n] = d
        rows.append((n, mean, mx, d["replay_hal_instr_mean"], us_entry))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print("B-G431B-ESC1 control interrupt (esc1_control_isr), Cortex-M4 instructions in QEMU,")
    print("%d running periods at %d r/min, %.1f N*m; time at 170 MHz for CPI 1.0 .. 1.5 incl. "
          "exception entry/exit; share of the 50 us period at 20 kHz" %
          (args.periods, args.speed, bench.TORQUE_NM))
    print("%-8s %10s %8s %14s %18s %14s" % ("ctrl", "mean", "max", "replay-HAL", "us (max)",
                                             "% of 50 us"))
    for n, mean, mx, rep, us in rows:
        print("%-8s %10.1f %8d %14.1f %8.2f .. %5.2f %6.1f .. %4.1f" %
              (n, mean, mx, rep, us[0], us[1], 100 * us[0] / 50.0, 100 * us[1] / 50.0))
    print("(replay-HAL: the same periods through bench_cm4's fw_isr with the replay HAL)")
    print("written: " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
