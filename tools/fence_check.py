#!/usr/bin/python3
"""The signal fences of the state shared between contexts, checked in the source.

    tools/fence_check.py [ROOT]

docs/architecture.md ("State shared between the contexts") gives each field
shared between the PWM interrupt, the medium-rate task and the main loop its
one writer and how it is published: data stored before a volatile count
behind a release signal fence, read after the other side's count behind an
acquire fence. A signal fence emits no instruction, so no test of the
program's behaviour sees one missing; with link-time optimisation a plain
store may then move past the count. This check reads the functions that
publish or consume a count (or take a step with the interrupts masked,
g4_irq_lock) and requires, in each, the listed steps in order:
a step is a regular expression over the function's text with comments
removed, and the next step is searched after the previous one's match. It
fails (exit 1) naming the function and the step not found in order.

--self-test removes each rule's fences (and locks) from its function in turn and fails
unless the rule then fails (the check's own failure path).

It catches a fence removed, or a store moved above its fence; not a field
that is missing from the tables, nor a publication in a function not listed.
"""
import os
import re
import sys

REL = r"(atomic_signal_fence\(memory_order_release\)|FW_RELEASE\(\))"
ACQ = r"atomic_signal_fence\(memory_order_acquire\)"
LOCK = r"[gf]4_irq_lock\(\)"  # the interrupts masked (PRIMASK) for the steps after it

# (file, function, [steps in order], what it publishes)
RULES = [
    # fw_t (firmware/isr): the main loop's side
    ("firmware/isr/pipeline.c", "fw_request", [REL, r"ml\.req\[k\] =", REL, r"ml\.req_sum ="],
     "a request's data before its count, the count before the sum"),
    ("firmware/isr/pipeline.c", "fw_set_torque_ref",
     [r"ml\.torque_ref =", r"ml\.torque_ref_lim =", REL, r"ml\.ref_mode ="],
     "the torque reference before its mode"),
    ("firmware/isr/pipeline.c", "fw_set_speed_ref", [r"ml\.speed_ref =", REL, r"ml\.ref_mode ="],
     "the speed reference before its mode"),
    ("firmware/isr/pipeline.c", "fw_tm_peek", [r"isr\.tm_head", ACQ, r"tm_ring\["],
     "a telemetry record read after its publication"),
    ("firmware/isr/pipeline.c", "fw_tm_release", [REL, r"ml\.tm_tail ="],
     "a telemetry record read before its slot is handed back"),
    # fw_t: the interrupt's and the medium task's side
    ("firmware/isr/pipeline.c", "fw_isr_fast", [r"tm_slot =", REL, r"isr\.tm_head ="],
     "a telemetry record before its publication"),
    ("firmware/isr/pipeline.c", "fw_mid_trigger", [r"in->", REL, r"mid_req = req"],
     "the medium task's input slot before its count"),
    ("firmware/isr/pipeline.c", "fw_mid_track_request", [r"in->", REL, r"mid_req = req"],
     "the tracker's input slot before its count"),
    ("firmware/isr/medium.c", "fw_medium",
     [r"mid_done == fw->mid_req", ACQ, r"in->", REL, r"mid_done = done", r"out->", REL,
      r"mid_done = done"],
     "the medium task's input after its count, its output before its count"),
    # the control interrupt held off and let go (NVIC, B-G431B-ESC1)
    ("hal/stm32g4/g4_core.c", "g4_nvic_enable", [REL, r"G4_NVIC_ISER"],
     "the reconfiguration before the interrupt can run again"),
    ("hal/stm32g4/g4_core.c", "g4_nvic_disable", [r"G4_NVIC_ICER", ACQ],
     "nothing moved above the interrupt's mask"),
    # USART2's byte rings (B-G431B-ESC1)
    ("firmware/apps/esc1/esc1_uart.c", "esc1_uart_getc",
     [r"rx_head", ACQ, r"u->rx\[", REL, r"rx_tail ="],
     "a received byte read after its count and before its slot is handed back"),
    ("firmware/apps/esc1/esc1_uart.c", "esc1_uart_write",
     [r"tx_tail", ACQ, r"u->tx\[", REL, r"tx_head\+\+"],
     "a byte to send stored in a freed slot and before its count"),
    ("firmware/apps/esc1/esc1_uart.c", "esc1_uart_irq",
     [r"rx_tail", ACQ, r"u->rx\[", REL, r"rx_head\+\+", r"tx_head", ACQ, r"u->tx\[", REL, r"tx_tail\+\+"],
     "the interrupt's side of both rings"),
    ("firmware/apps/esc1/esc1_uart.c", "esc1_uart_lost_idle",
     [LOCK, r"u->rx_lost;", r"u->rx_lost = 0u", r"g4_irq_unlock"],
     "a pending loss read and cleared with the interrupt masked (none noted meanwhile is lost)"),
    # the console's byte rings (STM32F405 boards: board_uart.c, filled and
    # drained by f405_uart.c's interrupt)
    ("firmware/apps/board/board_uart.c", "board_uart_getc",
     [r"rx_head", ACQ, r"u->rx\[", REL, r"rx_tail ="],
     "a received byte read after its count and before its slot is handed back"),
    ("firmware/apps/board/board_uart.c", "board_uart_write",
     [r"tx_tail", ACQ, r"u->tx\[", REL, r"tx_head\+\+"],
     "a byte to send stored in a freed slot and before its count"),
    ("firmware/apps/board/board_uart.c", "board_uart_rx",
     [r"rx_tail", ACQ, r"u->rx\[", REL, r"rx_head\+\+"],
     "a received byte stored in a freed slot and before its count"),
    ("firmware/apps/board/board_uart.c", "board_uart_tx_next",
     [r"tx_head", ACQ, r"u->tx\[", REL, r"tx_tail\+\+"],
     "a byte to send read after its count and before its slot is handed back"),
    # the console's pending loss (STM32F405 boards: board_uart.c under f405_uart.c's lock)
    ("firmware/apps/f405/f405_uart.c", "f405_uart_next",
     [LOCK, r"F4_USART_SR", r"board_uart_lost_idle\(", r"f4_irq_unlock"],
     "a pending loss read and cleared with the USART interrupt masked (none noted meanwhile is lost)"),
    # TIM1 BDTR.MOE (B-G431B-ESC1): set only with the trip checked, the interrupts masked
    ("hal/stm32g4/g4_hal.c", "hal_gate_enable",
     [LOCK, r"hal_trip_active\(h\)", r"g4_tim1_outputs\(true\)", r"g4_irq_unlock"],
     "MOE's read-modify-write with the break interrupt held off"),
]


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: " " * len(m.group(0)), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def function_body(text, name):
    """The text of the definition of `name` (its signature to its closing brace)."""
    m = re.search(r"^[A-Za-z_][^\n;]*\b" + re.escape(name) + r"\([^;{]*\)\s*\{", text, flags=re.M)
    if m is None:
        return None
    depth = 0
    for i in range(m.end() - 1, len(text)):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return text[m.start():i + 1]
    return None


def check(body, steps):
    """None when the steps match in order, else the index of the first that does not."""
    pos = 0
    for k, step in enumerate(steps):
        m = re.compile(step).search(body, pos)
        if m is None:
            return k
        pos = m.end()
    return None


def main(argv):
    self_test = "--self-test" in argv
    args = [a for a in argv[1:] if a != "--self-test"]
    root = args[0] if args else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    failed = 0
    for path, func, steps, what in RULES:
        with open(os.path.join(root, path), encoding="utf-8") as f:
            text = strip_comments(f.read())
        body = function_body(text, func)
        if body is None:
            print("fence_check: %s: %s() not found" % (path, func))
            failed += 1
            continue
        bad = check(body, steps)
        if not self_test:
            if bad is not None:
                print("fence_check: %s: %s(): %s: step %d (%s) not found in order"
                      % (path, func, what, bad, steps[bad]))
                failed += 1
            continue
        # self-test: every fence of the rule removed in turn must fail it
        for k, step in enumerate(steps):
            if step not in (REL, ACQ, LOCK):
                continue
            n = len(re.findall(step, body))
            for j in range(n):
                count = [0]

                def drop(m):
                    count[0] += 1
                    return " " * len(m.group(0)) if count[0] == j + 1 else m.group(0)

                if check(re.sub(step, drop, body), steps) is None:
                    print("fence_check --self-test: %s(): fence %d of step %d removed, the rule "
                          "still holds" % (func, j, k))
                    failed += 1
    n_rules = len(RULES)
    if failed:
        print("fence_check: %d failure(s) in %d rules" % (failed, n_rules))
        return 1
    print("fence_check: %d rules hold%s" % (n_rules, " and fail without their fences"
                                             if self_test else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
