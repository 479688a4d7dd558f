#!/usr/bin/python3
"""tools/flash without a board (ctest esc1_flash, vesc6_flash, odrive-v36_flash).

    test_flash.py ROOT IMAGE.elf [BOARD]

BOARD: b-g431b-esc1 (default), vesc6 or odrive-v36 (tools/flash --board): the
STM32F405 boards' openocd target is stm32f4x and st-flash writes the vector
table's sector and the rest apart (IMAGE.s0.bin at 0x0800_0000, IMAGE.app.bin
at 0x0800_C000), never the settings sectors between them.

  --dry-run (default tool, openocd, st-flash) prints the programmer's command
  with the image and exits 0; without an ST-LINK (PMSM_FLASH_USB_ROOT at an
  empty directory, so a probe on this machine is never touched) it exits 2
  with one line that says no ST-LINK probe was found; a fake ST-LINK entry
  (vendor 0483, product 374b) gets past that check in --dry-run; with it and a
  stand-in openocd on PATH (it prints openocd's program/verify lines, pausing
  between them), --progress streams those lines as they come, before the
  verdict; --which names the image; an unknown option and a missing image
  fail with a message.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time


def run(args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=e)
    return r.returncode, r.stdout, r.stderr


FAKE_OPENOCD = '''#!/bin/sh
echo "Open On-Chip Debugger (stand-in)"
echo "** Programming Started **"; sleep 0.4
echo "** Programming Finished **"; echo "** Verify Started **"; sleep 0.4
echo "** Verified OK **"; echo "** Resetting Target **"
'''


def check_progress(flash, elf, usb, check):
    """flash: the tools/flash command line for the board (a function of its
    arguments)."""
    """--progress streams the programmer's lines while it runs: the first
    arrives before the programmer ends (0.8 s of pauses), the verdict last."""
    with tempfile.TemporaryDirectory() as bindir:
        fake = os.path.join(bindir, "openocd")
        with open(fake, "w") as fh:
            fh.write(FAKE_OPENOCD)
        os.chmod(fake, 0o755)
        env = dict(os.environ, PMSM_FLASH_USB_ROOT=usb, PATH=bindir + os.pathsep + os.environ["PATH"])
        t0 = time.monotonic()
        p = subprocess.Popen(flash("--progress", "--tool", "openocd", elf), stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, env=env)
        seen = []
        for line in p.stdout:
            seen.append((time.monotonic() - t0, line.rstrip()))
        rc = p.wait()
        started = [t for t, l in seen if "Programming Started" in l]
        check(rc == 0 and started and started[0] < seen[-1][0] - 0.5 and
              "written and verified" in seen[-1][1] and any("Verified OK" in l for _, l in seen),
              "--progress: the programmer's lines as they come, then the verdict", repr(seen))


def main():
    root, elf = sys.argv[1], sys.argv[2]
    board = sys.argv[3] if len(sys.argv) > 3 else "b-g431b-esc1"
    f4 = board != "b-g431b-esc1"
    flash_tool = os.path.join(root, "tools", "flash")

    def flash(*args):
        return [flash_tool, "--board", board] + list(args)

    fails = []

    def check(ok, what, detail=""):
        print("%s: %s%s" % ("PASS" if ok else "FAIL", what, "" if ok else " -- " + detail))
        if not ok:
            fails.append(what)

    rc, out, err = run(flash("--dry-run", elf))
    check(rc == 0 and elf in out and ("openocd" in out or "st-flash" in out),
          "--dry-run prints the command", out + err)
    if shutil.which("openocd"):
        target = "stm32f4x" if f4 else "stm32g4x"
        rc, out, err = run(flash("--dry-run", "--tool", "openocd", elf))
        check(rc == 0 and "interface/stlink.cfg" in out and "target/%s.cfg" % target in out and
              "program" in out and "verify" in out and elf in out,
              "openocd: stlink + %s, program IMAGE verify reset exit" % target, out + err)
    if shutil.which("st-flash"):
        rc, out, err = run(flash("--dry-run", "--tool", "st-flash", elf))
        if f4:
            s0, app = elf[:-4] + ".s0.bin", elf[:-4] + ".app.bin"
            check(rc == 0 and out.split() == ["st-flash", "write", s0, "0x08000000;", "st-flash",
                                              "--reset", "write", app, "0x0800C000"],
                  "st-flash: IMAGE.s0.bin at 0x08000000, then IMAGE.app.bin at 0x0800C000 "
                  "(the settings sectors not written)", out + err)
        else:
            binf = elf[:-4] + ".bin"
            check(rc == 0 and out.split()[:3] == ["st-flash", "--reset", "write"] and
                  binf in out and "0x08000000" in out,
                  "st-flash: --reset write IMAGE.bin 0x08000000", out + err)
    with tempfile.TemporaryDirectory() as usb:
        rc, out, err = run(flash(elf), {"PMSM_FLASH_USB_ROOT": usb})
        lines = [l for l in (out + err).splitlines() if l.strip()]
        check(rc == 2 and len(lines) == 1 and "no ST-LINK" in lines[0] and
              (not f4 or "SWD connector" in lines[0]),
              "no probe: exit 2, one line 'no ST-LINK probe found'", out + err)
        dev = os.path.join(usb, "1-1")
        os.makedirs(dev)
        open(os.path.join(dev, "idVendor"), "w").write("0483\n")
        open(os.path.join(dev, "idProduct"), "w").write("374b\n")
        rc, out, err = run(flash("--dry-run", elf), {"PMSM_FLASH_USB_ROOT": usb})
        check(rc == 0, "a probe present: --dry-run still only prints", out + err)
        check_progress(flash, elf, usb, check)
    rc, out, err = run(flash("--which", "--tool", "st-flash", elf))
    if f4:
        check(rc == 0 and out.split() == [elf[:-4] + ".s0.bin", elf[:-4] + ".app.bin"],
              "--which: st-flash writes the two parts", out + err)
    else:
        check(rc == 0 and out.strip() == elf[:-4] + ".bin", "--which: st-flash writes the .bin",
              out + err)
    rc, out, err = run(flash("--bogus"))
    check(rc != 0 and "unknown option" in err, "unknown option refused", out + err)
    rc, out, err = run([flash_tool, "--board", "nosuch", elf])
    check(rc != 0 and "--board must be" in err, "unknown board refused", out + err)
    rc, out, err = run(flash("--dry-run", "/nonexistent/pmsm-esc1.elf"))
    check(rc != 0 and "no image" in err, "missing image named", out + err)
    print("%s: %d failed" % ("FAIL" if fails else "PASS", len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
