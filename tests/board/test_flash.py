#!/usr/bin/python3
"""tools/flash without a board (ctest esc1_flash, stm32g4 build).

    test_flash.py ROOT IMAGE.elf

  --dry-run (default tool, openocd, st-flash) prints the programmer's command
  with the image and exits 0; without an ST-LINK (PMSM_FLASH_USB_ROOT at an
  empty directory, so a probe on this machine is never touched) it exits 2
  with one line that says no ST-LINK probe was found; a fake ST-LINK entry
  (vendor 0483, product 374b) gets past that check in --dry-run; an unknown
  option and a missing image fail with a message.
"""
import os
import shutil
import subprocess
import sys
import tempfile


def run(args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=e)
    return r.returncode, r.stdout, r.stderr


def main():
    root, elf = sys.argv[1], sys.argv[2]
    flash = os.path.join(root, "tools", "flash")
    fails = []

    def check(ok, what, detail=""):
        print("%s: %s%s" % ("PASS" if ok else "FAIL", what, "" if ok else " -- " + detail))
        if not ok:
            fails.append(what)

    rc, out, err = run([flash, "--dry-run", elf])
    check(rc == 0 and elf in out and ("openocd" in out or "st-flash" in out),
          "--dry-run prints the command", out + err)
    if shutil.which("openocd"):
        rc, out, err = run([flash, "--dry-run", "--tool", "openocd", elf])
        check(rc == 0 and "interface/stlink.cfg" in out and "target/stm32g4x.cfg" in out and
              "program" in out and "verify" in out and elf in out,
              "openocd: stlink + stm32g4x, program IMAGE verify reset exit", out + err)
    if shutil.which("st-flash"):
        rc, out, err = run([flash, "--dry-run", "--tool", "st-flash", elf])
        binf = elf[:-4] + ".bin"
        check(rc == 0 and out.split()[:3] == ["st-flash", "--reset", "write"] and
              binf in out and "0x08000000" in out,
              "st-flash: --reset write IMAGE.bin 0x08000000", out + err)
    with tempfile.TemporaryDirectory() as usb:
        rc, out, err = run([flash, elf], {"PMSM_FLASH_USB_ROOT": usb})
        lines = [l for l in (out + err).splitlines() if l.strip()]
        check(rc == 2 and len(lines) == 1 and "no ST-LINK" in lines[0],
              "no probe: exit 2, one line 'no ST-LINK probe found'", out + err)
        dev = os.path.join(usb, "1-1")
        os.makedirs(dev)
        open(os.path.join(dev, "idVendor"), "w").write("0483\n")
        open(os.path.join(dev, "idProduct"), "w").write("374b\n")
        rc, out, err = run([flash, "--dry-run", elf], {"PMSM_FLASH_USB_ROOT": usb})
        check(rc == 0, "a probe present: --dry-run still only prints", out + err)
    rc, out, err = run([flash, "--bogus"])
    check(rc != 0 and "unknown option" in err, "unknown option refused", out + err)
    rc, out, err = run([flash, "--dry-run", "/nonexistent/pmsm-esc1.elf"])
    check(rc != 0 and "no image" in err, "missing image named", out + err)
    print("%s: %d failed" % ("FAIL" if fails else "PASS", len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
