#!/usr/bin/python3
"""Flash and RAM use of a firmware image against the chip's memories.

    image_size.py --size arm-none-eabi-size --flash BYTES --ram BYTES image.elf

Flash = every allocated section loaded from flash (code, constants, the
initial values of .data); RAM = .data + .bss + heap + the reserved stack
(sections placed at addresses >= 0x2000_0000). Prints one line each and exits
1 when either exceeds the limit (the linker's region checks fail first; this
is the second, explicit check with the numbers).
"""
import argparse
import subprocess
import sys

RAM_BASE = 0x20000000
FLASH_BASE = 0x08000000
FLASH_END = 0x10000000


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="arm-none-eabi-size")
    ap.add_argument("--flash", type=int, required=True)
    ap.add_argument("--ram", type=int, required=True)
    ap.add_argument("elf")
    a = ap.parse_args()
    out = subprocess.run([a.size, "-A", "-d", a.elf], check=True, stdout=subprocess.PIPE,
                         text=True).stdout
    flash = ram = 0
    stack = 0
    for line in out.splitlines():
        f = line.split()
        if len(f) != 3 or not f[1].isdigit() or not f[2].isdigit():
            continue
        name, size, addr = f[0], int(f[1]), int(f[2])
        if size == 0 or addr == 0:
            continue  # debug sections
        if FLASH_BASE <= addr < FLASH_END:
            flash += size
        elif addr >= RAM_BASE:
            ram += size
            if name == ".data":
                flash += size  # its initial values
            if name == ".stack":
                stack = size
    ok = flash <= a.flash and ram <= a.ram
    print("image %s: flash %d of %d bytes (%.1f %%), RAM %d of %d bytes (%.1f %%, "
          "incl. %d-byte stack)%s" % (a.elf.rsplit("/", 1)[-1], flash, a.flash,
                                      100.0 * flash / a.flash, ram, a.ram,
                                      100.0 * ram / a.ram, stack,
                                      "" if ok else "  -> DOES NOT FIT"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
