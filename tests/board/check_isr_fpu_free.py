#!/usr/bin/python3
"""The control interrupt's code of a board image without FPU instructions.

    check_isr_fpu_free.py IMAGE.elf HANDLER... [--steps]

The PWM-period interrupt and the medium-rate task are built without the FPU's
registers (pmsm_no_fpu, tools/cmake/pmsm_build.cmake): GCC otherwise moves
64-bit integers through d7, the handler then counts as FPU code and every
preemption of FPU code stacks the FP context (lazy stacking). This reads the
linked image's disassembly, follows the direct calls and branches from each
HANDLER, adds the controllers' step functions (reached through their
descriptors: every function named *_step), and fails (exit 1) naming each
function of that tree with a VFP instruction (v*: vmov, vldr, vstr, vpush,
...). Indirect calls other than the steps are not followed (tools/stack_check.py
does that for the B-G431B-ESC1 from its configuration).
"""
import re
import subprocess
import sys


def main(argv):
    elf, roots = argv[1], argv[2:]
    out = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf],
                         stdout=subprocess.PIPE, text=True, check=True).stdout
    funcs = {}
    cur = None
    for line in out.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:$", line)
        if m:
            cur = m.group(1)
            funcs[cur] = {"calls": set(), "vfp": []}
            continue
        p = line.split("\t")
        if cur is None or len(p) < 2 or not line.startswith(" "):
            continue
        mnem = p[1].strip()
        ops = p[2] if len(p) > 2 else ""
        if re.match(r"v[a-z]", mnem):
            funcs[cur]["vfp"].append(mnem)
        t = re.search(r"<([^>+]+)(\+0x[0-9a-f]+)?>", ops)
        if mnem.startswith("b") and t and t.group(1) != cur:
            funcs[cur]["calls"].add(t.group(1))
    missing = [r for r in roots if r not in funcs]
    if missing:
        print("FAIL %s not in %s" % (", ".join(missing), elf))
        return 1
    todo = list(roots) + [f for f in funcs if f.endswith("_step") or "_step." in f]
    seen = set()
    bad = []
    while todo:
        f = todo.pop()
        if f in seen or f not in funcs:
            continue
        seen.add(f)
        if funcs[f]["vfp"]:
            bad.append("%s (%s)" % (f, ", ".join(sorted(set(funcs[f]["vfp"])))))
        todo.extend(funcs[f]["calls"])
    if bad:
        print("FAIL FPU instructions in the control interrupt's code: " + "; ".join(sorted(bad)))
        return 1
    print("PASS %d functions from %s and the controllers' steps: no FPU instruction"
          % (len(seen), ", ".join(roots)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
