#!/usr/bin/python3
"""Checks an STM32F405 board image as the chip will boot it (no board needed).

    check_f4_image.py IMAGE.elf CONSOLE_IRQ NFAULT_IRQ CONTROLLER...

Reads the ELF (check_image.py's parsers) and the files beside it:
  - the vector table is the first thing in flash, at 0x0800_0000 (RM0090
    sec. 2.4: boot from main flash), 16 + 82 words; word 0 (initial SP) the
    top of the 128 KB SRAM, word 1 the reset handler;
  - IRQ 18 (ADC: the control interrupt), the console's USART interrupt and
    nFAULT's EXTI interrupt hold the application's handlers (Thumb);
    NMI, HardFault, MemManage, BusFault, UsageFault and every other IRQ
    vector are the gates-off fault handler f4_fault_handler;
  - nothing of the image in the settings sectors 1 and 2 (0x0800_4000 ..
    0x0800_BFFF): a settings save erases them; the image continues at
    0x0800_C000 (sector 3);
  - the image holds every controller of the core's registry (its
    ctrl_desc_<name> descriptors), and at least half of the 1 MB flash is
    free;
  - the .s0.bin beside it starts with the vector table and .app.bin with
    .text (what st-flash writes at 0x0800_0000 and 0x0800_C000); the .hex
    has no byte in the settings sectors; the .map exists.
Exit 0 when all hold; prints each check and the flash figures.
"""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_image import elf_sections  # noqa: E402

FLASH, FLASH_SIZE = 0x08000000, 1024 * 1024
SETTINGS_LO, SETTINGS_HI = 0x08004000, 0x0800C000
SRAM_TOP = 0x20000000 + 128 * 1024
N_VECTORS = 16 + 82
FAULTS = {2: "NMI", 3: "HardFault", 4: "MemManage", 5: "BusFault", 6: "UsageFault"}


def elf_all_symbols(data, secs_list, secs):
    """Every named symbol (functions and objects): name -> value."""
    sym = secs[".symtab"]
    strtab = secs_list[sym["link"]]
    syms = {}
    for i in range(sym["size"] // 16):
        name_off, value, size, info, other, shndx = struct.unpack_from(
            "<IIIBBH", data, sym["offset"] + 16 * i)
        off = strtab[4] + name_off
        name = data[off:data.index(b"\0", off)].decode()
        if name:
            syms.setdefault(name, value)
    return syms


def hex_addresses(path):
    """Start and end of every data record of an Intel hex file."""
    base = 0
    for line in open(path):
        line = line.strip()
        if not line.startswith(":"):
            continue
        n, addr, typ = int(line[1:3], 16), int(line[3:7], 16), int(line[7:9], 16)
        if typ == 4:
            base = int(line[9:13], 16) << 16
        elif typ == 0:
            yield base + addr, base + addr + n


def main():
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    elf, console_irq, nfault_irq = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    controllers = sys.argv[4:]
    data = open(elf, "rb").read()
    secs, secs_list = elf_sections(data)
    syms = elf_all_symbols(data, secs_list, secs)
    fails = []

    def check(ok, what):
        print("%s: %s" % ("PASS" if ok else "FAIL", what))
        if not ok:
            fails.append(what)

    vt = secs.get(".isr_vector")
    check(vt is not None and vt["addr"] == FLASH, ".isr_vector at 0x%08X" % FLASH)
    if vt is None:
        return 1
    words = struct.unpack_from("<%dI" % N_VECTORS, data, vt["offset"])
    check(words[0] == SRAM_TOP, "initial SP 0x%08X = top of the 128 KB SRAM" % words[0])
    check(words[1] == (syms.get("Reset_Handler", 0) | 1), "reset vector -> Reset_Handler (Thumb)")
    fault = syms.get("f4_fault_handler", 0) | 1
    check(fault != 1, "gates-off fault handler f4_fault_handler present")
    irqs = {18: "ADC_IRQHandler", console_irq: None, nfault_irq: None}
    for irq in sorted(irqs):
        w = words[16 + irq]
        name = irqs[irq]
        ok = w != fault and (name is None or w == (syms.get(name, 0) | 1)) and (w & 1) == 1
        check(ok, "IRQ %d -> the application's handler%s" % (irq, " " + name if name else ""))
    for v, name in FAULTS.items():
        check(words[v] == fault, "%s -> gates-off fault handler" % name)
    # the EXTI vectors share one handler in the application; the console's
    # USART handlers too: every vector that is not one of the used IRQs, an
    # EXTI line or a USART is the fault handler.
    shared = {6, 7, 8, 9, 10, 23, 40, 37, 38, 39, 52, 71, 24}
    others = [16 + i for i in range(82) if i not in irqs and i not in shared]
    check(all(words[i] == fault for i in others), "unused IRQ vectors -> gates-off fault handler")
    loaded = [(n, s) for n, s in secs.items() if s["size"] > 0 and FLASH <= s["addr"] < SRAM_TOP
              and s["addr"] < 0x10000000]
    check(all(s["addr"] + s["size"] <= SETTINGS_LO or s["addr"] >= SETTINGS_HI
              for _, s in loaded), "no section in the settings sectors 1 and 2")
    check(secs[".text"]["addr"] == SETTINGS_HI, ".text from 0x%08X (sector 3)" % SETTINGS_HI)
    used = sum(s["size"] for _, s in loaded)
    if ".data" in secs:
        used += secs[".data"]["size"]
    free = FLASH_SIZE - used
    print("flash: %d bytes used, %d free of 1 MB (%.1f %%); settings sectors 32768 bytes" %
          (used, free, 100.0 * free / FLASH_SIZE))
    check(free >= FLASH_SIZE // 2, "at least half of the 1 MB flash free")
    missing = [c for c in controllers if "ctrl_desc_" + c not in syms]
    check(not missing, "every controller of the registry in the image (%d)%s" %
          (len(controllers), ": missing " + " ".join(missing) if missing else ""))
    base = elf[:-4]
    s0, app = base + ".s0.bin", base + ".app.bin"
    check(os.path.exists(s0) and open(s0, "rb").read(8) == struct.pack("<II", *words[:2]),
          "%s starts with the vector table" % os.path.basename(s0))
    text = secs[".text"]
    first = data[text["offset"]:text["offset"] + 8]
    check(os.path.exists(app) and open(app, "rb").read(8) == first,
          "%s starts with .text" % os.path.basename(app))
    hexf = base + ".hex"
    check(os.path.exists(hexf) and all(e <= SETTINGS_LO or a >= SETTINGS_HI
                                       for a, e in hex_addresses(hexf)),
          "%s has no byte in the settings sectors" % os.path.basename(hexf))
    check(os.path.exists(base + ".map"), "%s exists" % os.path.basename(base + ".map"))
    print("%s: %d checks failed" % ("FAIL" if fails else "PASS", len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
