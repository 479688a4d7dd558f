#!/usr/bin/python3
"""A board image's messages carry their numbers: no float conversion that its libc drops.

    check_printf.py image.elf

newlib-nano prints nothing for %g/%e/%f unless _printf_float is linked, so a
format string with a float conversion in an image that links newlib-nano's
formatter without _printf_float would send its messages without their values.
The image's string literals (the .rodata*.str* input sections the linker map
beside the ELF places in flash) are scanned for conversions:
  - newlib's formatter linked (_svfprintf_r / _vfprintf_r / _svfiprintf_r)
    without _printf_float: no float conversion may appear;
  - the firmware's formatter (text_vformat, firmware/protocol/text_fmt.h) is
    libc's snprintf and vsnprintf (they are linked, newlib's formatter is
    not): every conversion must be one it supports.
Exit 0 when the image's messages can print every value they format.
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_image import elf_sections, elf_symbols  # noqa: E402

FLASH, FLASH_END = 0x08000000, 0x10000000
NEWLIB_FORMATTERS = ("_svfprintf_r", "_vfprintf_r", "_svfiprintf_r", "_vfiprintf_r")
# A printf conversion as C writes it (flags, width, precision, length, letter).
CONV = re.compile(rb"%[-+ #0]*(\d+|\*)?(\.(\d+|\*)?)?(hh|h|ll|l|j|z|t|L)?([a-zA-Z%])")
FLOAT_LETTERS = b"eEfFgGaA"
# text_fmt.h: %% %c %s %d %i %u %x, l/ll/z, precision; floats with a precision.
TEXT_FMT = re.compile(rb"%(\.\d+)?(ll|l|z)?[csdiux%]$|%(\.\d+)?[gGeEfF]$")


def image_strings(data, secs, map_text):
    """The NUL-terminated string literals of the map's .rodata*.str* input sections."""
    out = []
    for m in re.finditer(r"^ (\.rodata\S*\.str\S*)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)", map_text,
                         re.M):
        addr, size = int(m.group(2), 16), int(m.group(3), 16)
        if size == 0 or not FLASH <= addr < FLASH_END:
            continue
        sec = next((s for s in secs.values() if s["type"] == 1 and
                    s["addr"] <= addr < s["addr"] + s["size"]), None)
        if sec is None:
            continue
        off = sec["offset"] + addr - sec["addr"]
        out += [x for x in map(text_tail, data[off:off + size].split(b"\0")) if x]
    return out


def text_tail(s):
    """A literal ends at its NUL: the printable UTF-8 text that ends `s`. With
    link-time optimisation GCC may place a constant table in a string section
    too, with no NUL before the next literal; its bytes are no format."""
    u = s.decode("utf-8", "replace")
    i = len(u)
    while i > 0 and u[i - 1] != "\ufffd" and (u[i - 1].isprintable() or u[i - 1] in "\t\r\n"):
        i -= 1
    return u[i:].encode()


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    data = open(sys.argv[1], "rb").read()
    base = sys.argv[1][:-4] if sys.argv[1].endswith(".elf") else sys.argv[1]
    map_text = open(base + ".map").read()
    secs, secs_list = elf_sections(data)
    syms = elf_symbols(data, secs_list, secs)
    newlib = [n for n in NEWLIB_FORMATTERS if n in syms]
    float_linked = "_printf_float" in syms
    # snprintf/vsnprintf without newlib's formatter are libc_small.c's (with
    # link-time optimisation text_vformat may be inlined into them)
    ours = not newlib and ("snprintf" in syms or "vsnprintf" in syms)
    convs = []
    for s in image_strings(data, secs, map_text):
        for m in CONV.finditer(s):
            if m.group(0) == b"% " or s[m.start():m.start() + 3] in (b"% o", b"% f"):
                continue  # "10 % of": prose, not a conversion (no format has a space flag)
            if (m.group(0), s) not in convs:
                convs.append((m.group(0), s))
    fails = []
    if newlib and not float_linked:
        bad = [(c, s) for c, s in convs if c[-1:] in FLOAT_LETTERS]
        for c, s in bad:
            fails.append("newlib-nano formatter (%s) without _printf_float, float conversion %s in "
                         "%r" % (",".join(newlib), c.decode(), s.decode()[:80]))
    if ours:
        for c, s in convs:
            if not TEXT_FMT.match(c):
                fails.append("conversion %s unsupported by text_vformat in %r"
                             % (c.decode(), s.decode()[:80]))
    print("image: newlib formatter %s, _printf_float %s, the firmware's formatter as snprintf %s; "
          "%d conversions in %d strings" % (",".join(newlib) or "none",
                                             "linked" if float_linked else "absent",
                                             "yes" if ours else "no", len(convs),
                                             len({s for _, s in convs})))
    for f in fails:
        print("FAIL: " + f)
    print("PASS" if not fails else "FAIL: %d" % len(fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
