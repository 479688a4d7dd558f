#!/usr/bin/python3
"""./tools/sim --target board:DEV against a real STM32F405 PIL image in QEMU.

    qemu_f405_pil.py ROOT PIL.elf SERIAL_INDEX [SIM_ARGS...]

The board's processor-in-the-loop image (firmware/apps/f405_pil, built for
the board, unchanged) runs in QEMU 7.2's emulated STM32F405 (netduinoplus2)
with its console USART on a pseudo-terminal: to the simulator the same
kind of serial device as a USB serial adapter on the real board. QEMU starts
paused (-S); the test opens the terminal, lets the CPU run (the monitor's
"cont"), waits for the image's first byte (its transmit check, a frame
delimiter: the USART is up and every later byte arrives), closes it, then
runs ./tools/sim --target board:/dev/pts/N with SIM_ARGS (default: the
drone motor, FOC, 750 r/min, 0.1 N*m, 20 ms).

Passes when the simulator exits 0 and prints its metrics: every period's
samples went to the board image over the USART model, fw_isr ran there, and
its compare values came back within the link's time-out. QEMU's USART takes
one byte per main-loop wake-up (it does not ask for the next one when the
data register is read), so a period costs about a quarter of a second here:
the run is short. Each step is bounded in wall time.
"""
import os
import re
import select
import subprocess
import sys
import termios
import time
import tty

WAIT_PTY_S = 10.0
WAIT_BOOT_S = 30.0
SIM_S = 240.0
DEFAULT_SIM = ["--machine", "sim_host/machines/mj5208_drone.ini", "--controller", "foc",
               "--speed-rpm", "750", "--torque-ref", "0.1", "--duration", "0.02"]


def fail(msg, qemu=None):
    print("FAIL " + msg, flush=True)
    if qemu is not None:
        qemu.kill()
        qemu.wait()
    sys.exit(1)


def main():
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    root, elf, index = sys.argv[1], sys.argv[2], int(sys.argv[3])
    sim_args = sys.argv[4:] or DEFAULT_SIM
    cmd = ["qemu-system-arm", "-M", "netduinoplus2", "-display", "none", "-S",
           "-monitor", "stdio"] + ["-serial", "null"] * index + ["-serial", "pty",
                                                                  "-kernel", elf]
    qemu = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    os.set_blocking(qemu.stdout.fileno(), False)
    text, dev, end = b"", None, time.monotonic() + WAIT_PTY_S
    while dev is None and time.monotonic() < end:
        select.select([qemu.stdout], [], [], 0.2)
        text += qemu.stdout.read() or b""
        m = re.search(rb"char device redirected to (/dev/pts/\d+) \(label serial%d\)" % index,
                      text)
        dev = m.group(1).decode() if m else None
    if dev is None:
        fail("QEMU named no pseudo-terminal within %.0f s: %r" % (WAIT_PTY_S, text), qemu)
    print("ok   QEMU netduinoplus2 paused, the console USART on " + dev, flush=True)
    fd = os.open(dev, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    termios.tcflush(fd, termios.TCIOFLUSH)
    qemu.stdin.write(b"cont\n")
    qemu.stdin.flush()
    t0, got = time.monotonic(), b""
    while not got and time.monotonic() - t0 < WAIT_BOOT_S:
        r, _, _ = select.select([fd], [], [], 0.5)
        if r:
            got = os.read(fd, 64)
    os.close(fd)
    if not got:
        fail("the PIL image sent nothing within %.0f s (start-up hung?)" % WAIT_BOOT_S, qemu)
    print("ok   the image's USART is up (%r after %.1f s)" % (got[:8], time.monotonic() - t0),
          flush=True)
    t0 = time.monotonic()
    try:
        sim = subprocess.run([os.path.join(root, "tools", "sim")] + sim_args +
                             ["--target", "board:" + dev], cwd=root, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, timeout=SIM_S)
    except subprocess.TimeoutExpired:
        fail("./tools/sim --target board:%s did not end within %.0f s" % (dev, SIM_S), qemu)
    out = sim.stdout.decode(errors="replace")
    qemu.kill()
    qemu.wait()
    print(out.rstrip())
    if sim.returncode != 0:
        fail("./tools/sim --target board:%s exited %d" % (dev, sim.returncode))
    if "T_mean" not in out:
        fail("./tools/sim printed no metrics")
    print("ok   ./tools/sim --target board:%s: the run completed on the F405 image in %.1f s" %
          (dev, time.monotonic() - t0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
