#!/usr/bin/python3
"""Example outputs in the documentation, produced by the commands they show.

An example is a code block between two markers in a Markdown file:

    <!-- example NAME [label=L] [timeout=S] -->
        $ ./tools/sim --machine sim_host/machines/thesis_spmsm.ini --controller m2ptfc \\
            --speed-rpm 750 --torque-ref 1.8
        controller m2ptfc  fs 10000 Hz ...
    <!-- /example -->

Lines starting with "$ " are shell commands (a line ending in a backslash goes on);
the lines after a command, up to the next one, are what it prints: stdout and stderr
together, through a pseudo-terminal so that they interleave as on a terminal (ANSI
escapes dropped, a line redrawn with carriage returns shown as it ends). A command
that exits non-zero ends its output with "[exit N]". In the expected text, "..."
stands for any text within a line, and a line of "..." alone for any number of lines
(for what differs between runs: times, process ids, tokens).

Commands run in a scratch folder whose entries link to the repository's top level
(tools/, sim_host/, build/, ...; not out/), so an example reads the repository and
writes its files (m.json, out/report.md) into the scratch folder.

    doc_examples.py check [--label L] [NAME...]   run the examples, show differences, exit 1 on any
    doc_examples.py update [--label L] [NAME...]  write each example's actual output into its file
    doc_examples.py list                          the examples and where they are

Labels say what an example needs beyond the host build: host (the default; ctest
doc_examples in the host build), qemu (the cm4 images; ctest doc_examples_qemu in the
cm4 build). The check also fails on a transcript (a "$ " or "> " prompt followed by
what the program answered) in README.md or docs/ outside an example, unless the line
before its block is "<!-- transcript: WHY -->" saying why CI cannot produce it (a
board's output). docs/examples.md explains how to add one.
"""
import argparse
import difflib
import errno
import fcntl
import os
import pty
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import termios
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OPEN = re.compile(r"^<!-- example ([A-Za-z0-9_.-]+)((?: [a-z]+=[^ ]+)*) -->$")
CLOSE = "<!-- /example -->"
TRANSCRIPT = re.compile(r"^<!-- transcript: .+ -->$")
NOT_OUTPUT = re.compile(r"^<!-- not output: .+ -->$")
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]|\x1b[()][A-Za-z0-9]|\x1b[=>]")
LABELS = ("host", "qemu")
DEFAULT_TIMEOUT = 120.0
ENV = {"TERM": "dumb", "COLUMNS": "200", "LINES": "50", "LC_ALL": "C.UTF-8",
       "PMSM_PROGRESS": "none", "PMSM_STUDY_PROGRESS": "none", "PYTHONUNBUFFERED": "1"}


class Example:
    """One example: where it is, its options, its commands and their expected output."""

    def __init__(self, path, name, opts, first, last, prefix, fenced, lines):
        self.path, self.name, self.opts = path, name, opts
        self.first, self.last = first, last  # the block's lines [first, last) in the file
        self.prefix, self.fenced = prefix, fenced
        self.label = opts.get("label", "host")
        self.timeout = float(opts.get("timeout", DEFAULT_TIMEOUT))
        self.steps = parse_steps(lines)

    def where(self):
        return "%s:%d" % (os.path.relpath(self.path, ROOT), self.first + 1)


class DocError(Exception):
    pass


def parse_steps(lines):
    """[(command, its display lines, expected output lines)] of a block's text."""
    steps = []
    i = 0
    while i < len(lines):
        if not lines[i].startswith("$ "):
            if lines[i].strip():
                raise DocError("text before the first '$ ' command: %r" % lines[i])
            i += 1
            continue
        shown = [lines[i]]
        cmd = lines[i][2:]
        while cmd.endswith("\\") and i + 1 < len(lines):
            i += 1
            shown.append(lines[i])
            cmd = cmd + "\n" + lines[i]  # bash joins the two lines
        i += 1
        out = []
        while i < len(lines) and not lines[i].startswith("$ "):
            out.append(lines[i])
            i += 1
        while out and not out[-1].strip():
            out.pop()
        steps.append((cmd, shown, out))
    if not steps:
        raise DocError("no '$ ' command in the example")
    return steps


def block_lines(lines, i):
    """The code block starting at line i: (first, last, prefix, fenced, its text lines)."""
    if lines[i].startswith("```"):
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        if j == len(lines):
            raise DocError("unterminated ``` block")
        return i, j + 1, "", True, lines[i + 1:j]
    if lines[i].startswith("    "):
        j = i
        while j < len(lines) and (lines[j].startswith("    ") or (
                not lines[j].strip() and j + 1 < len(lines) and lines[j + 1].startswith("    "))):
            j += 1
        return i, j, "    ", False, [ln[4:] for ln in lines[i:j]]
    raise DocError("expected a code block (indented by four spaces or fenced with ```)")


def parse_file(path):
    """The examples of one Markdown file, and its transcripts outside examples."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    examples, loose = [], []
    i = 0
    while i < len(lines):
        m = OPEN.match(lines[i].rstrip())  # at the line's start: not one shown in a block
        if lines[i].startswith("<!-- example") and not m:
            raise DocError("%s:%d: malformed marker (expected <!-- example NAME [key=value] -->)"
                           % (path, i + 1))
        if m:
            opts = dict(kv.split("=", 1) for kv in m.group(2).split())
            bad = [k for k in opts if k not in ("label", "timeout")]
            if bad or opts.get("label", "host") not in LABELS:
                raise DocError("%s:%d: example %s: options label=%s, timeout=SECONDS (got %s)" % (
                    path, i + 1, m.group(1), "|".join(LABELS), m.group(2).strip()))
            j = i + 1
            while j < len(lines) and not lines[j].strip():
                j += 1
            if j == len(lines):
                raise DocError("%s:%d: example %s has no block" % (path, i + 1, m.group(1)))
            try:
                first, last, prefix, fenced, text = block_lines(lines, j)
                ex = Example(path, m.group(1), opts, first, last, prefix, fenced, text)
            except DocError as e:
                raise DocError("%s:%d: example %s: %s" % (path, j + 1, m.group(1), e))
            k = last
            while k < len(lines) and not lines[k].strip():
                k += 1
            if k == len(lines) or lines[k].rstrip() != CLOSE:
                raise DocError("%s:%d: example %s: expected %s after its block" % (
                    path, last + 1, m.group(1), CLOSE))
            examples.append(ex)
            i = k + 1
            continue
        if lines[i].startswith("```") or (lines[i].startswith("    ") and lines[i].strip() and (
                i == 0 or not lines[i - 1].strip())):
            try:
                first, last, _prefix, _fenced, text = block_lines(lines, i)
            except DocError:
                i += 1
                continue
            k = first - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            marker = lines[k].rstrip() if k >= 0 else ""
            kind = block_kind(text)
            excused = TRANSCRIPT.match(marker) or (kind == "other" and NOT_OUTPUT.match(marker))
            if kind != "commands" and not excused:
                loose.append("%s:%d" % (os.path.relpath(path, ROOT), first + 1))
            i = last
            continue
        i += 1
    return examples, loose


# Programs a block of commands may name beside the repository's own executables.
COMMANDS = {"cmake", "ctest", "git", "sudo", "openocd", "st-flash", "dask", "python3",
            "qemu-system-arm", "gdb-multiarch", "arm-none-eabi-gdb", "apt-get", "ninja", "cd"}


def is_command(line):
    """A line a user types: a program of the repository (tools/demo, ./tools/sim,
    build/...) or one of COMMANDS, with its arguments (after sudo or VAR=value)."""
    words = line.split()
    while words and (words[0] == "sudo" or re.match(r"^[A-Z_][A-Z0-9_]*=", words[0])):
        words = words[1:]  # sudo, an environment variable's assignment
    if words in ([], ["\\"]):
        return words != line.split()  # assignments alone, the command on the next line
    w = words[0]
    if w in COMMANDS:
        return True
    path = os.path.join(ROOT, w[2:] if w.startswith("./") else w)
    return "/" in w and (os.access(path, os.X_OK) and os.path.isfile(path)
                         or w.startswith("build/") or w.startswith("./build/"))


def block_kind(text):
    """What a code block outside an example shows: "commands" (lines to type: commands,
    prompts without answers, comments, asides), "transcript" (a prompt, "$ " or "> ",
    followed by what the program answered) or "other" (a program's output without a
    prompt, or text that is no command: equations, a file's format). A line of "..."
    or in parentheses is the writer's aside."""
    prompt = answer = False
    continued = False
    for ln in text:
        s = ln.strip()
        if continued:
            continued = s.endswith("\\")
            continue
        if not s or s.startswith("...") or s.startswith("(") or s.startswith("#"):
            continue
        continued = s.endswith("\\")
        if s.startswith("$ ") or s.startswith("> "):
            prompt = True
        elif prompt:
            return "transcript"
        elif not is_command(s):
            answer = True
    return "other" if answer else "commands"


def is_transcript(text):
    return block_kind(text) == "transcript"


def markdown_files():
    r = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", "*.md"],
                       cwd=ROOT, capture_output=True, text=True)
    files = r.stdout.split() if r.returncode == 0 else []
    if not files:  # not a git checkout (a source tarball): every .md below the root
        for d, subdirs, names in os.walk(ROOT):
            subdirs[:] = [s for s in subdirs if s not in (".git", "build", "out")]
            files += [os.path.relpath(os.path.join(d, n), ROOT) for n in names if n.endswith(".md")]
    return sorted(os.path.join(ROOT, f) for f in files)


def collect():
    examples, loose = [], []
    for path in markdown_files():
        ex, lo = parse_file(path)
        examples += ex
        rel = os.path.relpath(path, ROOT)
        if rel == "README.md" or rel.startswith("docs" + os.sep):
            loose += lo
    names = {}
    for ex in examples:
        if ex.name in names:
            raise DocError("example %s twice: %s and %s" % (ex.name, names[ex.name], ex.where()))
        names[ex.name] = ex.where()
    return examples, loose


# ------------------------------------------------------------------ running

def scratch_dir():
    d = tempfile.mkdtemp(prefix="doc-example-")
    for entry in os.listdir(ROOT):
        if entry in (".git", "out"):
            continue
        os.symlink(os.path.join(ROOT, entry), os.path.join(d, entry))
    return d


def run_pty(cmd, cwd, timeout):
    """Run cmd with bash on a pseudo-terminal; (exit status or None on time-out, output)."""
    master, slave = pty.openpty()
    attrs = termios.tcgetattr(slave)
    attrs[1] &= ~termios.ONLCR  # no "\r\n" for "\n"
    termios.tcsetattr(slave, termios.TCSANOW, attrs)
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 50, 200, 0, 0))
    env = dict(os.environ)
    env.update(ENV)
    p = subprocess.Popen(["bash", "-c", cmd], cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                         stdout=slave, stderr=slave, start_new_session=True)
    os.close(slave)
    chunks = []
    t_end = time.monotonic() + timeout
    timed_out = False
    while True:
        left = t_end - time.monotonic()
        if left <= 0:
            timed_out = True
            break
        r, _, _ = select.select([master], [], [], min(left, 1.0))
        if not r:
            if p.poll() is not None:
                # the program has ended; what a child it left running writes is not its output
                r, _, _ = select.select([master], [], [], 0.2)
                if not r:
                    break
            else:
                continue
        try:
            data = os.read(master, 65536)
        except OSError as e:
            if e.errno == errno.EIO:
                break
            raise
        if not data:
            break
        chunks.append(data)
    if timed_out:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    rc = p.wait()
    os.close(master)
    return (None if timed_out else rc), clean(b"".join(chunks).decode("utf-8", "replace"))


def clean(text):
    """Terminal output as lines: escapes dropped, a redrawn line as it ends, right-stripped."""
    out = []
    for ln in ANSI.sub("", text).split("\n"):
        ln = ln.rstrip("\r")
        if "\r" in ln:
            ln = ln.rsplit("\r", 1)[1]
        out.append(ln.rstrip())
    while out and not out[-1]:
        out.pop()
    return out


def pattern(expected):
    """The regular expression of expected lines with their "..." wildcards."""
    parts = []
    for ln in expected:
        s = ln.rstrip()
        if s.strip() == "...":
            parts.append(r"(?:[^\n]*\n)*?")
        else:
            parts.append(".*?".join(re.escape(x) for x in s.split("...")) + r"\n")
    return re.compile("".join(parts))


def matches(expected, actual):
    return pattern(expected).fullmatch("".join(a + "\n" for a in actual)) is not None


def run_example(ex):
    """[(command, expected, actual)] of each step; actual ends with [exit N] if N != 0."""
    d = scratch_dir()
    try:
        res = []
        for cmd, _shown, expected in ex.steps:
            rc, actual = run_pty(cmd, d, ex.timeout)
            if rc is None:
                actual.append("[timed out after %g s]" % ex.timeout)
            elif rc != 0:
                actual.append("[exit %d]" % rc)
            res.append((cmd, expected, actual))
        return res
    finally:
        shutil.rmtree(d, ignore_errors=True)


# ------------------------------------------------------------------ commands

def select_examples(examples, a):
    chosen = [e for e in examples if (not a.names or e.name in a.names)
              and (a.label is None or e.label == a.label)]
    unknown = set(a.names) - {e.name for e in examples}
    if unknown:
        raise DocError("no example named %s (doc_examples.py list)" % ", ".join(sorted(unknown)))
    return chosen


def cmd_check(a):
    examples, loose = collect()
    chosen = select_examples(examples, a)
    failed = 0
    for ex in chosen:
        t0 = time.monotonic()
        bad = [(c, e, x) for c, e, x in run_example(ex) if not matches(e, x)]
        dt = time.monotonic() - t0
        if not bad:
            print("ok    %-28s %-34s %5.1f s" % (ex.name, ex.where(), dt), flush=True)
            continue
        failed += 1
        print("FAIL  %-28s %-34s %5.1f s" % (ex.name, ex.where(), dt), flush=True)
        for cmd, expected, actual in bad:
            print("  $ " + cmd.replace("\n", "\n    "))
            # a line its wildcards match is shown as printed: the diff names what differs
            shown = [a if i < len(actual) and e.strip() != "..." and matches([e], [a]) else e
                     for i, (e, a) in enumerate(zip(expected, actual + [""] * len(expected)))]
            for ln in difflib.unified_diff(shown, actual, "documented", "printed now",
                                           lineterm="", n=2):
                print("  " + ln)
    if not a.names and a.label in (None, "host"):
        for path in loose:
            print("FAIL  output outside an example: %s (a program's answer, or a block that "
                  "is no list of commands: wrap it in <!-- example NAME --> ... "
                  "<!-- /example -->; or say why CI cannot produce it, <!-- transcript: WHY -->, "
                  "or what it is if no program prints it, <!-- not output: WHAT -->, on the "
                  "line before it; docs/examples.md)" % path)
        failed += len(loose)
    print("doc_examples: %d example(s) checked, %d failed%s" % (
        len(chosen), failed, "" if not failed else
        " (tools/doc_examples.py update NAME writes what the commands print now)"))
    return 1 if failed else 0


def cmd_update(a):
    examples, _loose = collect()
    chosen = select_examples(examples, a)
    by_file = {}
    for ex in chosen:
        by_file.setdefault(ex.path, []).append(ex)
    for path, exs in by_file.items():
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
        for ex in sorted(exs, key=lambda e: -e.first):  # from the end: earlier indices hold
            body = []
            for (cmd, shown, expected), (_c, _e, actual) in zip(ex.steps, run_example(ex)):
                body += shown
                body += expected if matches(expected, actual) else actual
            text = [ex.prefix + ln if ln else "" for ln in body]
            if ex.fenced:
                text = [lines[ex.first]] + text + ["```"]
            lines[ex.first:ex.last] = text
            print("updated %s (%s)" % (ex.name, ex.where()))
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(lines))
    return 0


def cmd_list(_a):
    examples, loose = collect()
    for ex in examples:
        print("%-28s %-6s %s" % (ex.name, ex.label, ex.where()))
    for path in loose:
        print("%-28s %-6s %s" % ("(not an example)", "", path))
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("check", "update"):
        p = sub.add_parser(name)
        p.add_argument("--label", choices=LABELS)
        p.add_argument("names", nargs="*")
    sub.add_parser("list")
    a = ap.parse_args(argv)
    try:
        return {"check": cmd_check, "update": cmd_update, "list": cmd_list}[a.cmd](a)
    except DocError as e:
        print("doc_examples: %s" % e, file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
