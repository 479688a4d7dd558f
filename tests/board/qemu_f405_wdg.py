#!/usr/bin/python3
"""The start-up of an STM32F405 board image against its watchdog windows.

    qemu_f405_wdg.py SOURCE_DIR IMAGE.elf

The independent watchdog runs from step 1 of the start-up with the window
F405_IMAGE_BOOT (firmware/apps/f405/f405_app.h: F405_IWDG_BOOT_MS) and must
not expire before the main loop first refreshes it, whatever the clock: the
start-up that ran on the fall-back HSI (16 MHz, a crystal that does not
start) is the longest. QEMU's STM32F405 runs exactly that path (no RCC: the
HSE never starts). The instructions from the reset handler to the main
loop's first refresh (f4_iwdg_refresh) are counted exactly with the QEMU
counting plugin (tools/bench_fw/bench_plugin.c; every time-out's polling
included, which on the chip takes its stated time instead: a bound from
above), and those from the firmware's initialisation (fw_init) to that
refresh, which a settings record in flash adds once more (its apply runs
fw_init again; QEMU's erased sectors hold none). The time they take on the chip at 16 MHz, at the CPI of 1.5 the
bench assumes (docs/f405.md: no flash wait state at 16 MHz), must lie
within the window's shortest time-out (the LSI at its fastest, 47 kHz:
DS8626). About 10 s (QEMU is stopped once the image idles).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

F_HSI = 16e6
CPI = 1.5
LSI_TYP, LSI_MAX = 32000.0, 47000.0


def main():
    src, elf = sys.argv[1], sys.argv[2]
    hdr = open(os.path.join(src, "firmware/apps/f405/f405_app.h")).read()
    boot_ms = int(re.search(r"#define F405_IWDG_BOOT_MS (\d+)u", hdr).group(1))
    shortest_s = boot_ms / 1000.0 * LSI_TYP / LSI_MAX
    syms = {}
    nm = subprocess.run(["arm-none-eabi-nm", elf], stdout=subprocess.PIPE, text=True, check=True)
    for line in nm.stdout.splitlines():
        p = line.split()
        if len(p) == 3:
            syms[p[2]] = int(p[0], 16) & ~1
    for s in ("Reset_Handler", "f4_iwdg_refresh", "fw_init"):
        if s not in syms:
            print("FAIL %s not in %s" % (s, elf))
            return 1
    work = tempfile.mkdtemp(prefix="qemu_f405_wdg.")
    try:
        # Two copies of the plugin (each its own counters): the start-up, and
        # the firmware's initialisation to the same first refresh.
        plugins = [os.path.join(work, "plugin%d.so" % k) for k in range(2)]
        subprocess.run(["cc", "-shared", "-fPIC", "-O2", "-o", plugins[0],
                        os.path.join(src, "tools/bench_fw/bench_plugin.c")], check=True)
        shutil.copy(plugins[0], plugins[1])
        outs = [os.path.join(work, "count%d.txt" % k) for k in range(2)]
        args = []
        for k, begin in enumerate((syms["Reset_Handler"], syms["fw_init"])):
            args += ["-plugin", "%s,out=%s,begin=%x,end=%x"
                     % (plugins[k], outs[k], begin, syms["f4_iwdg_refresh"])]
        # The image idles in its main loop once started: QEMU is stopped
        # after a bounded time; the plugin writes its counts at exit.
        subprocess.run(["timeout", "-s", "TERM", "10", "qemu-system-arm", "-machine",
                        "netduinoplus2", "-display", "none", "-monitor", "none",
                        "-serial", "null", "-serial", "null", "-serial", "null",
                        "-serial", "null"] + args + ["-kernel", elf],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        counts = []
        for out in outs:
            n = None
            if os.path.exists(out):
                for line in open(out):
                    p = line.split()
                    if p and p[0] == "S" and n is None:
                        n = int(p[2])
            counts.append(n)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    total, fw = counts
    if total is None or fw is None:
        print("FAIL the main loop never refreshed the watchdog (f4_iwdg_refresh not reached)")
        return 1
    # A settings record in flash is applied at start-up through fw_init once
    # more (QEMU's erased sectors hold none): its count added.
    worst = total + fw
    t = worst * CPI / F_HSI
    print("start-up to the first refresh: %d instructions, fw_init to it %d; with a settings "
          "record applied %d = %.2f s at 16 MHz, CPI %.1f" % (total, fw, worst, t, CPI))
    print("boot window F405_IWDG_BOOT_MS %d ms: shortest %.2f s (LSI at 47 kHz)"
          % (boot_ms, shortest_s))
    if t > shortest_s:
        print("FAIL the start-up on the HSI outlasts the boot window: the watchdog would reset "
              "the chip before the console answers")
        return 1
    print("PASS")
    return 0

if __name__ == "__main__":
    sys.exit(main())
