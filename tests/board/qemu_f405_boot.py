#!/usr/bin/python3
"""Boots a real STM32F405 board image in QEMU's emulated STM32F405.

    qemu_f405_boot.py IMAGE.elf TAG SERIAL_INDEX CONSOLE_IRQ [STACK_CHECK ARGS...]

QEMU 7.2's netduinoplus2 machine is an STM32F405 whose USARTs, TIM2-5, ADCs,
SPI, SYSCFG, EXTI and NVIC are modelled; RCC, the flash interface, GPIO,
TIM1/TIM8, DMA and the watchdogs read as zero and ignore writes. So the
image (built for the board, unchanged) meets a crystal that never starts, a
watchdog whose clock never runs, a DRV8301 that never answers on SPI and no
PWM interrupt, and must say each by name, hold its gates off and keep its
console: the board's USART is QEMU's serial SERIAL_INDEX (0 = USART1,
2 = USART3, 3 = UART4), its interrupt CONSOLE_IRQ.

Run 1 (the settings sectors erased, as on a new board):
  - start-up lines: reset cause (RCC reads 0: "unknown"), the clock's
    fall-back to HSI naming the HSE, the watchdog's LSI not running, the
    DRV8301 silent ("no answer on SPI"), "gates held off", the settings
    ("no record"), the stack's high-water mark: the start-up code painted
    the stack, so what the start-up used is found below the whole (an
    unpainted stack reads as all of it used) and above what its deepest path
    (the settings' defaults through fw_init) must have used, STACK_MIN_B;
    "status" gives the mark again, never lower, after every command below;
    after "config default" (the deepest command path: the command
    interpreter, the settings' defaults, fw_init) the mark must stay within
    the static worst case of the image that STACK_CHECK (tools/stack_check.py
    and its arguments, run beside QEMU) computes: what ran is bounded by the
    analysis, or the analysis misses a frame;
  - help, status (state, armed=0), config show (no record: refused naming
    why), arm (refused: "err 8 state gates held off: DRV8301 no answer ..."),
    fault (the fault report: none latched), config save (the erase path with
    the watchdog's erase window; QEMU's flash ignores writes: refused naming
    the flash), and status again after it: the console still answers.
Run 2 (a fault and the watchdog path): the console interrupt's vector
patched to an address with no memory (a copy of the image; the flash as a
corrupted image would hold it); one byte typed: the bus fault's handler
turns the gates off, records the fault, waits for the independent watchdog
(none in QEMU), resets the chip itself (SYSRESETREQ); the next start-up
reports "previous run stopped: BusFault at pc 0x30000000 ... instruction bus
error ... its gates were turned off".
Each wait is bounded (a hang fails the test by name); exit 0 when all hold.
"""
import os
import queue
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time

FLASH = 0x08000000
SETTINGS, SETTINGS_SIZE = 0x08004000, 0x8000
BAD_HANDLER = 0x30000001  # Thumb address of nothing (no memory at 0x3000_0000)
WAIT_S = 10.0             # one expected line or answer
RUN_S = 60.0              # one QEMU run, at most
# Below what the start-up's path to the default configuration (settings with
# no record -> board_app_reconfigure -> fw_init -> fw_setup_machine) must
# use: fw_setup_machine's frame alone is 1.7 KiB in these images (its
# -fstack-usage figure; tools/stack_check.py prints the path).
STACK_MIN_B = 2048

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)
    return ok


class Qemu:
    """QEMU with the board's USART on stdin/stdout, read line by line."""

    def __init__(self, elf, serial_index, flash_blobs):
        cmd = ["qemu-system-arm", "-M", "netduinoplus2", "-display", "none",
               "-monitor", "none"]
        cmd += ["-serial", "null"] * serial_index + ["-serial", "stdio"]
        for path, addr in flash_blobs:
            cmd += ["-device", "loader,file=%s,addr=0x%08x" % (path, addr)]
        cmd += ["-kernel", elf]
        self.t0 = time.monotonic()
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT)
        self.lines = queue.Queue()
        self.log = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for raw in self.proc.stdout:
            self.lines.put(raw.decode(errors="replace").rstrip("\r\n"))
        self.lines.put(None)

    def expect(self, needle, what, wait=WAIT_S):
        """The first line holding needle (lines before it are kept in the log)."""
        end = time.monotonic() + min(wait, RUN_S - (time.monotonic() - self.t0))
        while True:
            left = end - time.monotonic()
            if left <= 0:
                check(False, "%s: no line with %r within %.0f s (hang?)" % (what, needle, wait))
                return None
            try:
                line = self.lines.get(timeout=left)
            except queue.Empty:
                continue
            if line is None:
                check(False, "%s: QEMU ended before %r" % (what, needle))
                return None
            self.log.append(line)
            if needle in line:
                return line

    def send(self, text):
        self.proc.stdin.write(text.encode() + b"\r\n")
        self.proc.stdin.flush()

    def answer(self, command):
        """The first response line ("ok ..." / "err ...") of a command."""
        self.send(command)
        end = time.monotonic() + WAIT_S
        while time.monotonic() < end:
            try:
                line = self.lines.get(timeout=max(0.0, end - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            self.log.append(line)
            if line.startswith("ok") or line.startswith("err"):
                return line
        check(False, "%r: no answer within %.0f s" % (command, WAIT_S))
        return ""

    def items(self):
        """The item lines ("  key=value") that follow an "ok N" answer."""
        out = []
        while True:
            try:
                line = self.lines.get(timeout=0.5)
            except queue.Empty:
                return out
            if line is None:
                return out
            self.log.append(line)
            out.append(line.strip())

    def close(self):
        self.proc.kill()
        self.proc.wait()
        return time.monotonic() - self.t0


def elf_patch(path, addr, word):
    """Writes a 32-bit word at a load address of a copy of an ELF32 (LE)."""
    data = bytearray(open(path, "rb").read())
    e_phoff, = struct.unpack_from("<I", data, 28)
    e_phentsize, e_phnum = struct.unpack_from("<HH", data, 42)
    for i in range(e_phnum):
        p_type, p_offset, p_vaddr, p_paddr, p_filesz = struct.unpack_from(
            "<IIIII", data, e_phoff + i * e_phentsize)
        if p_type == 1 and p_paddr <= addr and addr + 4 <= p_paddr + p_filesz:
            struct.pack_into("<I", data, p_offset + addr - p_paddr, word)
            return bytes(data)
    raise SystemExit("no loadable segment holds 0x%08x" % addr)


def stack_items(items):
    """(used, size) of status's "stack_used=N size=M" item(s)."""
    st = [re.match(r"stack_used=(\d+) size=(\d+)$", i) for i in items]
    return [(int(x.group(1)), int(x.group(2))) for x in st if x]


def run_console(elf, tag, serial_index, erased):
    q = Qemu(elf, serial_index, [(erased, SETTINGS)])
    p = tag + ": "
    check(q.expect(p + "reset: ", "reset cause") is not None, "start-up: reset cause said")
    line = q.expect(p + "clock failed: ", "clock fall-back") or ""
    check("HSE" in line and "HSI 16 MHz" in line,
          "clock: no HSE in QEMU, fall-back to HSI named: " + line)
    line = q.expect(p + "watchdog: ", "watchdog") or ""
    check("LSI not running" in line and "gates held off" in line,
          "watchdog: its LSI not running named, gates held off: " + line)
    line = q.expect(p + "gates held off: ", "hold") or ""
    check("DRV8301 no answer on SPI" in line,
          "DRV8301 silent on QEMU's SPI: reported by name, gates held off: " + line)
    line = q.expect(p + "settings: ", "settings") or ""
    check("no record" in line, "settings: erased sectors read as no record: " + line)
    line = q.expect(p + "stack: ", "stack") or ""
    m = re.search(r"stack: (\d+) of (\d+) B used \(high-water mark\)", line)
    used, size = (int(m.group(1)), int(m.group(2))) if m else (0, 0)
    check(m is not None and STACK_MIN_B <= used < size,
          "start-up: the stack's high-water mark from the painting, %d <= used < size "
          "(an unpainted stack reads as size): %s" % (STACK_MIN_B, line))
    time.sleep(0.3)  # the console is up once the stack line is out
    q.stack = (used, size)

    a = q.answer("help")
    items = q.items()
    check(a.startswith("ok") and any(i.startswith("config save") for i in items),
          "help answers with the command list (%d lines)" % len(items))
    a = q.answer("status")
    items = q.items()
    check(a.startswith("ok") and "armed=0" in items and any(i.startswith("state=") for i in items),
          "status answers, not armed: " + " ".join(items[:2]))
    a = q.answer("config show")
    check(a.startswith("err 8 state settings: no record"),
          "config show answers: no record in flash: " + a)
    a = q.answer("arm")
    check(a.startswith("err 8 state gates held off: DRV8301 no answer on SPI"),
          "arm refused naming the cause: " + a)
    a = q.answer("status")
    items = q.items()
    check("armed=0" in items, "still not armed after the refused arm")
    a = q.answer("fault")
    check(a.startswith("ok fault 0 none"), "fault report runs (none latched): " + a)
    t = time.monotonic()
    a = q.answer("config save")
    check(a.startswith("err 10 failed flash: "),
          "config save runs the erase path (watchdog's erase window) and names QEMU's "
          "unwritable flash: %s (%.2f s)" % (a, time.monotonic() - t))
    a = q.answer("status")
    items = q.items()
    check(a.startswith("ok"), "the console answers after the erase path")
    st = stack_items(items)
    check(len(st) == 1 and st[0][1] == q.stack[1] and q.stack[0] <= st[0][0] < st[0][1],
          "status: the high-water mark after the commands, not below the start-up's, below "
          "the size: %s (start-up %d of %d B)" % (st, q.stack[0], q.stack[1]))
    a = q.answer("config default")
    check(a.startswith("ok compiled-in defaults applied"), "config default runs: " + a)
    a = q.answer("status")
    st = stack_items(q.items())
    q.stack_deep = st[0][0] if len(st) == 1 else None
    check(q.stack_deep is not None and q.stack[0] <= q.stack_deep < q.stack[1],
          "status after config default: the high-water mark %s B (start-up %d B)" %
          (q.stack_deep, q.stack[0]))
    wall = q.close()
    check(wall < RUN_S, "run 1 took %.1f s of wall time" % wall)
    return q.log, q.stack_deep


def run_fault(elf, tag, serial_index, console_irq, erased, tmp):
    bad = os.path.join(tmp, "fault.elf")
    open(bad, "wb").write(elf_patch(elf, FLASH + 4 * (16 + console_irq), BAD_HANDLER))
    q = Qemu(bad, serial_index, [(erased, SETTINGS)])
    p = tag + ": "
    check(q.expect(p + "settings: ", "first start-up") is not None,
          "run 2: the patched image starts")
    time.sleep(0.3)
    q.send("h")  # the console's interrupt: its vector leads nowhere
    line = q.expect(p + "previous run stopped: ", "fault report after the reset") or ""
    check("BusFault at pc 0x30000000" in line and "instruction bus error" in line,
          "the bus fault reported after the reset, by name and address: " + line)
    check("gates were turned off" in line, "the report says the gates were turned off")
    check(q.expect(p + "gates held off: DRV8301", "second start-up") is not None,
          "the second start-up runs to the console (gates held off)")
    wall = q.close()
    check(wall < RUN_S, "run 2 took %.1f s of wall time" % wall)
    return q.log


def main():
    if len(sys.argv) < 5:
        raise SystemExit(__doc__)
    elf, tag, serial_index, console_irq = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(
        sys.argv[4])
    if shutil.which("qemu-system-arm") is None:
        raise SystemExit("qemu-system-arm not found (tools/setup installs it)")
    # the static analysis, beside the emulator
    static = None
    if len(sys.argv) > 5:
        static = subprocess.Popen([sys.executable] + sys.argv[5:], stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True)
    tmp = tempfile.mkdtemp(prefix="qemu_f405_")
    logs = []
    deep = None
    try:
        erased = os.path.join(tmp, "erased.bin")
        open(erased, "wb").write(b"\xff" * SETTINGS_SIZE)
        print("== run 1: start-up and console of %s ==" % os.path.basename(elf))
        log, deep = run_console(elf, tag, serial_index, erased)
        logs.append(log)
        print("== run 2: a fault, the watchdog path, the report after the reset ==")
        logs.append(run_fault(elf, tag, serial_index, console_irq, erased, tmp))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if static is not None:
        out = static.communicate(timeout=300)[0]
        worst = re.search(r"worst case (\d+) B", out)
        thread = re.search(r"^\s+thread\s+\S+\s+(\d+) B", out, re.M)
        if check(worst is not None and thread is not None,
                 "the static stack check ran (%s)" % " ".join(sys.argv[5:7])):
            w, t = int(worst.group(1)), int(thread.group(1))
            check(deep is not None and deep <= w,
                  "measured after config default %s B <= the static worst case %d B (its "
                  "main-loop path alone %d B: measured %s)" %
                  (deep, w, t, "%.1f %% of it" % (100.0 * deep / t) if deep else "-"))
        else:
            print(out)
    if failures:
        for n, log in enumerate(logs, 1):
            print("---- console, run %d ----\n%s" % (n, "\n".join(log)))
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
