#!/usr/bin/python3
"""Checks a B-G431B-ESC1 image as the chip will boot it (no board needed).

    check_image.py build/b-g431b-esc1/firmware/apps/esc1/pmsm-esc1.elf

Reads the ELF (section and symbol tables, parsed here) and the .bin beside it:
  - the vector table is the first thing in flash, at 0x0800_0000 (RM0440 boot
    from main flash: the core fetches the initial SP and the reset vector there),
    and the .bin (what st-flash writes at 0x0800_0000) starts with it;
  - word 0 (initial SP) is the top of the 32 KiB SRAM, word 1 the reset handler;
  - IRQ 24 (TIM1_BRK_TIM15), 18 (ADC1_2: the control interrupt) and 38 (USART2)
    hold the application's handlers, with Thumb bit set, inside .text;
  - NMI, HardFault, MemManage, BusFault, UsageFault and every unused vector
    are the gates-off fault handler; with the flash driver linked (the settings
    store; its function g4_flash_begin), NMI is the flash driver's NMI_Handler instead, which
    separates the flash's ECC double-error NMI (a read result of the store)
    from any other NMI, sent to the fault handler (hal/stm32g4/g4_flash.c,
    tested on the host in test_g4_flash.c);
  - the reset handler starts the independent watchdog (IWDG_KR = 0xCCCC,
    RM0440 IWDG) before it calls anything (the data and bss set-up, main):
    a fault or a hang anywhere after the reset vector ends in a watchdog
    reset, not in a silent halt (read from its disassembly, the registers'
    values followed through literal loads and immediates);
  - the .hex and .map files exist beside the .elf.
Exit 0 when all hold; prints each check.
"""
import os
import re
import struct
import subprocess
import sys

IWDG_KR = 0x40003000
IWDG_START = 0xCCCC

FLASH = 0x08000000
SRAM_TOP = 0x20000000 + 32 * 1024
IRQ = {"ADC1_2_IRQHandler": 18, "TIM1_BRK_TIM15_IRQHandler": 24, "USART2_IRQHandler": 38}
FAULTS = {2: "NMI", 3: "HardFault", 4: "MemManage", 5: "BusFault", 6: "UsageFault"}
N_VECTORS = 16 + 102


def elf_sections(data):
    if data[:4] != b"\x7fELF" or data[4] != 1 or data[5] != 1:
        raise SystemExit("not a little-endian ELF32 file")
    e_shoff, = struct.unpack_from("<I", data, 0x20)
    e_shentsize, e_shnum, e_shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    secs = []
    for i in range(e_shnum):
        secs.append(struct.unpack_from("<IIIIIIIIII", data, e_shoff + i * e_shentsize))
    names = secs[e_shstrndx]
    out = {}
    for s in secs:
        off = names[4] + s[0]
        name = data[off:data.index(b"\0", off)].decode()
        out[name] = {"type": s[1], "addr": s[3], "offset": s[4], "size": s[5], "link": s[6]}
    return out, secs


def elf_symbols(data, secs_list, secs):
    sym = secs[".symtab"]
    strtab = secs_list[sym["link"]]
    syms = {}
    for i in range(sym["size"] // 16):
        name_off, value, size, info, other, shndx = struct.unpack_from(
            "<IIIBBH", data, sym["offset"] + 16 * i)
        off = strtab[4] + name_off
        name = data[off:data.index(b"\0", off)].decode()
        if name and (info & 0xF) == 2:  # STT_FUNC
            syms.setdefault(name, value)
    return syms


def word_at(data, secs, addr):
    for s in secs.values():
        if s["type"] == 1 and s["addr"] <= addr < s["addr"] + s["size"]:
            return struct.unpack_from("<I", data, s["offset"] + addr - s["addr"])[0]
    return None


def iwdg_started_first(elf, data, secs):
    """True when Reset_Handler stores 0xCCCC to IWDG_KR before its first call."""
    out = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf],
                         capture_output=True, text=True, check=True).stdout
    body = re.search(r"<Reset_Handler>:\n(.*?)\n\n", out, re.S)
    if body is None:
        return False
    regs = {}
    for line in body.group(1).splitlines():
        m = re.match(r"\s*[0-9a-f]+:\s+(\S+)\s*(.*)", line)
        if not m:
            continue
        op, args = m.group(1), m.group(2).split("@")
        ops = args[0].strip()
        note = args[1] if len(args) > 1 else ""
        dst = ops.split(",")[0].strip()
        if op.startswith("bl") or op.startswith("blx"):
            return False  # a call before the watchdog's start
        lit = re.search(r"\(([0-9a-f]+) <", note)
        imm = re.search(r"#(-?\d+)$", ops)
        if op.startswith("ldr") and lit and "[pc" in ops:
            regs[dst] = word_at(data, secs, int(lit.group(1), 16))
        elif op.split(".")[0] in ("mov", "movw", "movs") and imm:
            regs[dst] = int(imm.group(1)) & 0xFFFFFFFF
        elif op.startswith("str"):
            m2 = re.match(r"(\w+), \[(\w+)(?:, #(-?\d+))?\]$", ops)
            if m2 and regs.get(m2.group(1)) == IWDG_START and \
                    regs.get(m2.group(2)) is not None and \
                    regs[m2.group(2)] + int(m2.group(3) or 0) == IWDG_KR:
                return True
        elif dst in regs:
            regs.pop(dst)  # any other write: its value no longer known
    return False


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    elf = sys.argv[1]
    data = open(elf, "rb").read()
    secs, secs_list = elf_sections(data)
    syms = elf_symbols(data, secs_list, secs)
    fails = []

    def check(ok, what):
        print("%s: %s" % ("PASS" if ok else "FAIL", what))
        if not ok:
            fails.append(what)

    vt = secs.get(".isr_vector")
    check(vt is not None and vt["addr"] == FLASH,
          ".isr_vector at 0x%08X (boot from main flash)" % FLASH)
    if vt is None:
        return 1
    check(vt["size"] == 4 * N_VECTORS, "%d vectors (16 system + 102 STM32G431 IRQs)" % N_VECTORS)
    first = min(s["addr"] for n, s in secs.items() if s["addr"] >= FLASH and s["size"] > 0 and
                s["addr"] < 0x10000000)
    check(first == FLASH, "nothing in flash before the vector table")
    words = struct.unpack_from("<%dI" % N_VECTORS, data, vt["offset"])
    text = secs[".text"]

    def in_text(a):
        return text["addr"] <= (a & ~1) < text["addr"] + text["size"]

    check(words[0] == SRAM_TOP, "initial SP 0x%08X = top of the 32 KiB SRAM" % words[0])
    check(words[1] == (syms.get("Reset_Handler", 0) | 1) and in_text(words[1]),
          "reset vector -> Reset_Handler (Thumb)")
    fault = syms.get("g4_fault_handler")
    check(fault is not None, "gates-off fault handler g4_fault_handler present")
    for name, irq in IRQ.items():
        a = syms.get(name)
        w = words[16 + irq]
        check(a is not None and w == (a | 1) and in_text(w) and (a | 1) != ((fault or 0) | 1),
              "IRQ %d -> %s (the application's handler, Thumb, in .text)" % (irq, name))
    for v, name in FAULTS.items():
        if name == "NMI" and "g4_flash_begin" in syms:
            a = syms.get("NMI_Handler")
            check(a is not None and words[v] == (a | 1) and in_text(words[v])
                  and (a | 1) != ((fault or 0) | 1),
                  "NMI -> the flash driver's NMI_Handler (flash driver linked)")
            continue
        check(words[v] == ((fault or 0) | 1), "%s -> gates-off fault handler" % name)
    used = {16 + i for i in IRQ.values()}
    others = [i for i in range(16, N_VECTORS) if i not in used and i != 16 + 25 and i != 16 + 30]
    check(all(words[i] == ((fault or 0) | 1) for i in others),
          "unused IRQ vectors -> gates-off fault handler")
    check(iwdg_started_first(elf, data, secs),
          "Reset_Handler starts the independent watchdog (IWDG_KR = 0xCCCC) before any call")
    base = elf[:-4] if elf.endswith(".elf") else elf
    binf = base + ".bin"
    check(os.path.exists(binf) and open(binf, "rb").read(8) == struct.pack("<II", *words[:2]),
          "%s starts with the vector table" % os.path.basename(binf))
    for ext in (".hex", ".map"):
        check(os.path.exists(base + ext), "%s exists" % os.path.basename(base + ext))
    print("%s: %d checks failed" % ("FAIL" if fails else "PASS", len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
