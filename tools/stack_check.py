#!/usr/bin/python3
"""Worst static stack depth of a Cortex-M image, every entry point, interrupts nested.

    tools/stack_check.py --elf IMAGE.elf --config IMAGE_stack.json [--su-dir DIR ...]
                         [--limit 0.75] [--verbose]

What it computes, from the linked image (the code that runs, after link-time
optimisation):

  frames     each function's own frame: the -fstack-usage figure of its
             compile (GCC's .su files: <object>.su, <image>.ltrans<N>.ltrans.su
             for what link-time optimisation compiled), and for functions no
             .su covers (newlib, libgcc) the frame its prologue sets up (push,
             stmdb, vpush, sub sp), read from the disassembly. Where both
             exist the larger is taken; a function that moves the stack
             pointer again after its prologue (alloca, a variable-length
             array) or a .su entry marked "dynamic" fails the check.
  call graph bl and the branches that leave a function (tail calls) from the
             disassembly; every indirect call (blx rN, bx rN other than lr)
             is resolved through the image's configuration: its "indirect"
             entries map the source function the call is written in (as
             addr2line -i names it, inlined callers included) to the possible
             targets, given as function names or as the function pointers
             stored in data objects (a controller's descriptor, a command
             table). An indirect call no entry covers, a target set that
             resolves to nothing, and recursion fail the check.
  entries    the configuration's priority levels, lowest first: the thread
             (Reset_Handler) and each exception level with its handlers
             (the deepest handler of a level counts; one handler per level
             can be active). Each level above the thread adds the exception
             frame the hardware pushes onto the interrupted stack: 8 words,
             26 words when the interrupted code has used the FPU (its call
             tree holds a VFP instruction: lazy stacking reserves the
             extended frame), plus 4 bytes of alignment.
  result     the thread's depth plus every level's frame and handler, against
             the reserved stack (__stack_top__ - __stack_bottom__); more than
             --limit of it (default 75 %) fails. "fpu_free" entries fail when
             their call tree holds a VFP instruction.

Exit status 0 within the limit, 1 above it or on an error of the analysis.
"""
import argparse
import bisect
import glob
import json
import os
import re
import struct
import subprocess
import sys

TOOL = "arm-none-eabi-"
FRAME_BASIC = 32          # r0-r3, r12, lr, pc, xPSR
FRAME_FP = 32 + 72        # + s0-s15, FPSCR, reserved
FRAME_ALIGN = 4           # STKALIGN: the frame starts 8-byte aligned


def run(args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("stack_check: %s failed: %s" % (args[0], r.stderr.strip()))
    return r.stdout


def base_name(name):
    """A symbol without GCC's clone and LTO suffixes' numbers: foo.constprop.0.isra.0
    -> foo.constprop.isra; foo.lto_priv.0 -> foo (the .su files name them so)."""
    name = re.sub(r"\.lto_priv\.\d+", "", name)
    return re.sub(r"\.(\d+)(?=\.|$)", "", name)


def source_name(name):
    """foo.constprop.0 -> foo: the function as written in the source."""
    return name.split(".")[0]


class Elf:
    """The few parts of an ELF32 little-endian image the check needs."""

    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            self.data = f.read()
        d = self.data
        if d[:4] != b"\x7fELF" or d[4] != 1 or d[5] != 1:
            raise SystemExit("stack_check: %s is not a 32-bit little-endian ELF" % path)
        shoff, = struct.unpack_from("<I", d, 0x20)
        shentsize, shnum, shstrndx = struct.unpack_from("<HHH", d, 0x2E)
        secs = [struct.unpack_from("<IIIIIIIIII", d, shoff + i * shentsize) for i in range(shnum)]
        strtab = secs[shstrndx]
        self.sections = []
        for s in secs:
            name = d[strtab[4] + s[0]:d.index(b"\0", strtab[4] + s[0])].decode()
            self.sections.append({"name": name, "type": s[1], "flags": s[2], "addr": s[3],
                                  "offset": s[4], "size": s[5]})
        self.funcs = {}    # name -> (address without the Thumb bit, size)
        self.objects = {}  # name -> (address, size)
        self.symbols = {}  # every symbol's value
        for line in run([TOOL + "readelf", "-sW", path]).splitlines():
            p = line.split()
            if len(p) < 8 or not p[0].endswith(":"):
                continue
            try:
                value, size = int(p[1], 16), int(p[2])
            except ValueError:
                continue
            kind, name = p[3], p[7]
            self.symbols.setdefault(name, value)
            if kind == "FUNC":
                self.funcs[name] = (value & ~1, size)
            elif kind == "OBJECT" and size > 0:
                self.objects[name] = (value, size)

    def words(self, addr, size):
        """The 32-bit words of [addr, addr + size) in the loaded image."""
        for s in self.sections:
            if s["type"] in (1, 14, 16) and s["addr"] <= addr and addr + size <= s["addr"] + s["size"]:
                off = s["offset"] + addr - s["addr"]
                return [struct.unpack_from("<I", self.data, off + k)[0]
                        for k in range(0, size - size % 4, 4)]
        return []


INSN = re.compile(r"^\s*([0-9a-f]+):\s+(\S+)\s*(.*)$")
TARGET = re.compile(r"\b([0-9a-f]+) <([^>+]+)(\+0x[0-9a-f]+)?>")
REGLIST = re.compile(r"\{([^}]*)\}")


def reg_count(text):
    m = REGLIST.search(text)
    if not m:
        return 0
    n = 0
    for part in m.group(1).split(","):
        part = part.strip()
        if "-" in part:
            a, b = part.split("-")
            n += int(b[1:]) - int(a[1:]) + 1
        elif part:
            n += 1
    return n


class Function:
    def __init__(self, name, addr, size):
        self.name, self.addr, self.size = name, addr, size
        self.insns = []          # (address, mnemonic, operands)
        self.calls = set()       # direct callees (bl, tail branches)
        self.indirect = []       # addresses of indirect call sites
        self.prologue = 0        # bytes its prologue pushes and reserves
        self.sp_moves = []       # later stack-pointer adjustments (dynamic)
        self.vfp = []            # (address, instruction) of VFP instructions
        self.su = None           # -fstack-usage bytes

    def frame(self):
        return max(self.prologue, self.su or 0)


def disassemble(elf):
    funcs = {}
    by_addr = {}
    # one function per address; of aliases (the weak vectors) the name they
    # alias, not a _Handler name
    for name, (addr, size) in sorted(elf.funcs.items(),
                                     key=lambda kv: (kv[0].endswith("Handler"), kv[0])):
        if size > 0 and addr not in by_addr:
            f = Function(name, addr, size)
            funcs[name] = f
            by_addr[addr] = f
    starts = sorted(by_addr)
    cur = None
    for line in run([TOOL + "objdump", "-d", "--no-show-raw-insn", elf.path]).splitlines():
        m = re.match(r"^([0-9a-f]+) <([^>]+)>:$", line)
        if m:
            cur = by_addr.get(int(m.group(1), 16))
            continue
        m = INSN.match(line)
        if not m or cur is None:
            continue
        addr, mnem, ops = int(m.group(1), 16), m.group(2), m.group(3)
        if mnem.startswith("."):
            continue  # literal pool
        if addr >= cur.addr + cur.size:
            continue
        cur.insns.append((addr, mnem, ops.split("@")[0].strip()))
    for f in funcs.values():
        analyse(f, by_addr, starts)
    return funcs, by_addr


def containing(by_addr, starts, addr):
    k = bisect.bisect_right(starts, addr) - 1
    if k < 0:
        return None
    f = by_addr[starts[k]]
    return f if addr < f.addr + f.size else None


def analyse(f, by_addr, starts):
    in_prologue = True
    for addr, mnem, ops in f.insns:
        base = re.sub(r"(\.w|\.n)$", "", mnem)
        if base.startswith("v"):
            f.vfp.append((addr, mnem + " " + ops))  # every VFP instruction starts with v
        # the frame the prologue sets up, up to the first branch
        pushes = 0
        if base == "push" or (base == "stmdb" and ops.startswith("sp!")):
            pushes = 4 * reg_count(ops)
        elif base == "vpush":
            # d registers: 8 bytes; s registers: 4
            pushes = (8 if "d" in REGLIST.search(ops).group(1) else 4) * reg_count(ops)
        elif base in ("str", "strd") and ops.endswith("]!") and "[sp, #-" in ops:
            pushes = int(re.search(r"#-(\d+)", ops).group(1))
        elif base in ("sub", "subw") and re.match(r"sp, (sp, )?#\d+", ops):
            pushes = int(re.search(r"#(\d+)", ops).group(1))
        elif base == "sub" and ops.startswith("sp,") and "#" not in ops:
            f.sp_moves.append((addr, mnem + " " + ops))  # sp minus a register: dynamic
        if pushes:
            if in_prologue:
                f.prologue += pushes
            elif base in ("sub", "subw"):
                f.sp_moves.append((addr, mnem + " " + ops))
        if re.match(r"(b|bl|blx|bx|cb|cbz|cbnz|tbb|tbh)(eq|ne|cs|cc|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|hs|lo)?$",
                    base) or base in ("cbz", "cbnz"):
            in_prologue = False
        if base in ("pop", "ldmia") and "pc" in ops:
            in_prologue = False
        # calls and tail calls
        if base == "bl":
            t = TARGET.search(ops)
            if t:
                callee = by_addr.get(int(t.group(1), 16))
                if callee is not None:
                    f.calls.add(callee.name)
        elif base in ("blx", "bx") and re.match(r"^(r\d+|ip)$", ops):
            f.indirect.append(addr)
        elif re.match(r"^b(eq|ne|cs|cc|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|hs|lo)?$", base):
            t = TARGET.search(ops)
            if t:
                dest = int(t.group(1), 16)
                if not f.addr <= dest < f.addr + f.size:
                    # a tail call, or (libgcc) a jump into a shared tail of
                    # another function: that function's frame from there on
                    # is at most its whole frame
                    callee = containing(by_addr, starts, dest)
                    if callee is None:
                        raise SystemExit("stack_check: %s branches to %x, outside every "
                                         "function" % (f.name, dest))
                    f.calls.add(callee.name)
        elif base in ("blx",) and TARGET.search(ops):
            callee = by_addr.get(int(TARGET.search(ops).group(1), 16))
            if callee is not None:
                f.calls.add(callee.name)


def read_su(dirs, funcs):
    """The .su figures onto the image's functions (matched by their base names)."""
    by_base = {}
    for name in funcs:
        by_base.setdefault(base_name(name), []).append(name)
    dynamic = []
    files = []
    for d in dirs:
        files += glob.glob(os.path.join(d, "**", "*.su"), recursive=True)
    for path in files:
        with open(path) as fh:
            for line in fh:
                parts = line.rstrip("\n").split("\t")
                if len(parts) != 3:
                    continue
                name = parts[0].rsplit(":", 1)[-1]
                size, kind = int(parts[1]), parts[2]
                for fn in by_base.get(base_name(name), []):
                    f = funcs[fn]
                    f.su = max(f.su or 0, size)
                    if "dynamic" in kind and "bounded" not in kind:
                        dynamic.append((fn, path))
    return dynamic, len(files)


def inline_chain(elf, addrs):
    """addr -> the function names addr2line -i gives (innermost first)."""
    out = {}
    if not addrs:
        return out
    text = run([TOOL + "addr2line", "-e", elf.path, "-f", "-i", "-a"] +
               ["0x%x" % a for a in addrs])
    cur = None
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("0x"):
            cur = int(lines[i], 16)
            out[cur] = []
            i += 1
            continue
        out[cur].append(source_name(lines[i]))
        i += 2
    return out


def resolve_targets(spec, elf, funcs):
    """A target set: "name:REGEX" (functions by source name), "table:REGEX"
    (the function pointers stored in the data objects so named), "section:REGEX"
    (those stored in the sections so named); A&B: the functions of both."""
    if "&" in spec:
        sets = [resolve_targets(part, elf, funcs) for part in spec.split("&")]
        return set.intersection(*sets)
    kind, _, pat = spec.partition(":")
    rx = re.compile("^(?:%s)$" % pat)
    found = set()
    if kind == "name":
        found = {n for n in funcs if rx.match(source_name(n))}
    elif kind == "table":
        starts = {f.addr | 1: f.name for f in funcs.values()}
        for oname, (addr, size) in elf.objects.items():
            if rx.match(source_name(oname)):
                for w in elf.words(addr, size):
                    if w in starts:
                        found.add(starts[w])
    elif kind == "section":
        starts = {f.addr | 1: f.name for f in funcs.values()}
        for sec in elf.sections:
            if rx.match(sec["name"]) and sec["type"] in (1, 14, 16):  # PROGBITS, (PRE)INIT_ARRAY
                for w in elf.words(sec["addr"], sec["size"]):
                    if w in starts:
                        found.add(starts[w])
    else:
        raise SystemExit("stack_check: target %r: expected name:, table: or section:REGEX" %
                         spec)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elf", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--su-dir", action="append", default=[],
                    help="folder searched (recursively) for .su files (default: the ELF's build "
                         "folder, two levels up)")
    ap.add_argument("--limit", type=float, default=0.75)
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    with open(a.config) as fh:
        cfg = json.load(fh)
    elf = Elf(a.elf)
    funcs, by_addr = disassemble(elf)
    su_dirs = a.su_dir or [os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(a.elf))))]
    dynamic, n_su = read_su(su_dirs, funcs)
    errors = []
    if n_su == 0:
        errors.append("no .su files under %s (build with -fstack-usage)" % ", ".join(su_dirs))
    for fn, path in dynamic:
        errors.append("%s: dynamic stack use (%s)" % (fn, path))

    # indirect calls through the configuration's map
    sites = [(f, addr) for f in funcs.values() for addr in f.indirect]
    chains = inline_chain(elf, [addr for _, addr in sites])
    entries = []
    for e in cfg.get("indirect", []):
        targets = set()
        for spec in e["targets"]:
            t = resolve_targets(spec, elf, funcs)
            if not t and not e.get("may_be_empty"):
                errors.append("indirect target %r resolves to no function" % spec)
            targets |= t
        entries.append((re.compile("^(?:%s)$" % e["callers"]), targets, e))
    used = set()
    for f, addr in sites:
        chain = chains.get(addr, [])
        inner = chain[0] if chain else source_name(f.name)
        hit = [k for k, (rx, _, _) in enumerate(entries) if rx.match(inner)]
        if not hit:
            errors.append("indirect call at 0x%x in %s (written in %s): no \"indirect\" entry "
                          "covers it" % (addr, f.name, inner))
            continue
        for k in hit:
            used.add(k)
            f.calls |= entries[k][1]
    for k, (_, _, e) in enumerate(entries):
        if k not in used:
            errors.append("indirect entry for %r matches no call site" % e["callers"])

    # depth of every function: its frame plus its deepest callee
    depth, path, vfp_in = {}, {}, {}
    active = []

    def visit(name):
        if name in depth:
            return depth[name]
        if name in active:
            cyc = active[active.index(name):] + [name]
            raise SystemExit("stack_check: recursion: %s" % " -> ".join(cyc))
        active.append(name)
        f = funcs[name]
        best, best_path = 0, []
        # the first VFP instruction of its call tree: (function, address, text)
        vfp = (f.name,) + f.vfp[0] if f.vfp else None
        for c in sorted(f.calls):
            d = visit(c)
            if d > best:
                best, best_path = d, path[c]
            vfp = vfp or vfp_in[c]
        for addr, ins in f.sp_moves:
            errors.append("%s: stack pointer moved after the prologue at 0x%x (%s)" %
                          (name, addr, ins))
        active.pop()
        depth[name] = f.frame() + best
        path[name] = [name] + best_path
        vfp_in[name] = vfp
        return depth[name]

    def entry_functions(h):
        """The image's function(s) of an entry name (an alias such as
        HardFault_Handler is the function at its address)."""
        if h in elf.funcs:
            f = by_addr.get(elf.funcs[h][0])
            return [f.name] if f is not None else []
        return [n for n in funcs if source_name(n) == h]

    reserved = elf.symbols["__stack_top__"] - elf.symbols["__stack_bottom__"]
    print("stack_check: %s: reserved stack %d B (__stack_bottom__ .. __stack_top__)" %
          (os.path.basename(a.elf), reserved))
    total = 0
    below_fp = False
    report = []
    for lvl in cfg["levels"]:
        handlers = []
        for h in lvl["entries"]:
            names = entry_functions(h)
            if not names:
                if lvl.get("optional"):
                    continue
                errors.append("entry %s is not in the image" % h)
                continue
            for n in names:
                handlers.append((visit(n), n))
        if not handlers:
            continue
        d, n = max(handlers)
        frame = 0
        if lvl["name"] != "thread":
            frame = (FRAME_FP if below_fp else FRAME_BASIC) + FRAME_ALIGN
        total += frame + d
        uses_fp = any(vfp_in[h] for _, h in handlers)
        report.append((lvl["name"], n, d, frame, uses_fp, path[n]))
        below_fp = below_fp or uses_fp
    for name, n, d, frame, uses_fp, p in report:
        print("  %-10s %-28s %5d B%s%s" % (name, n, d,
                                            "  + exception frame %d B" % frame if frame else "",
                                            "  (uses the FPU)" if uses_fp else ""))
        if a.verbose:
            print("             " + " -> ".join("%s %d" % (x, funcs[x].frame()) for x in p))
    for h in cfg.get("fpu_free", []):
        names = entry_functions(h)
        if not names:
            errors.append("fpu_free: %s is not in the image" % h)
        for n in names:
            visit(n)
            if vfp_in[n]:
                fn, addr, ins = vfp_in[n]
                errors.append("%s must not use the FPU (its preemption would stack the FP "
                              "context): %s at 0x%x: %s" % (h, fn, addr, ins))
    share = total / reserved if reserved else 1.0
    print("stack_check: worst case %d B of %d B reserved (%.1f %%), limit %.0f %% (%d B)" %
          (total, reserved, 100 * share, 100 * a.limit, int(a.limit * reserved)))
    if share > a.limit:
        errors.append("worst case %d B is above %.0f %% of the reserved %d B" %
                      (total, 100 * a.limit, reserved))
    for e in errors:
        print("stack_check: FAIL: " + e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
