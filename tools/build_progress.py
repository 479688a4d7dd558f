"""Build a CMake target with a progress bar: the count of build steps and the
time left, for a tool that needs an image it can build itself (tools/console's
interactive QEMU image, pil_interactive.elf; tools/sim's simulator and PIL image;
./tools/demo's builds).

    python3 tools/build_progress.py BUILD_DIR TARGET [LABEL]

builds TARGET in the configured BUILD_DIR with the bar on stderr, silently when it
is up to date (the log in BUILD_DIR/TARGET-build.log; on failure its last lines and
exit status 1).

    ok, why = ensure_built(root, "cm4", "pil_interactive", elf_path)

Configures build/<preset> when it has never been configured (cmake --preset),
then runs `cmake --build build/<preset> --target <target>` (nothing to do when
the image is up to date). Progress comes from Ninja's status lines
("[done/total] description", NINJA_STATUS): on a terminal one bar redrawn in
place, otherwise a line every 10 %; a "[0/n]" line (CMake re-checking its
globs before the build proper) does not count. The estimate of the time left is the mean
time per step so far times the steps left. A build that runs another build
inside one of its steps (the interactive image generates its plant data with a
host build) prints that build's lines when the step ends: only lines with the
first total seen count.
"""
import os
import re
import shutil
import subprocess
import sys
import time

STATUS = re.compile(r"^\[(\d+)/(\d+)\] (.*)$")
NEEDS = {"cm4": ["cmake", "ninja", "arm-none-eabi-gcc"],
         "host-release": ["cmake", "ninja", "gcc", "pkg-config"]}


class Bar:
    """Progress of one build on a stream: a bar on a terminal, lines otherwise."""

    def __init__(self, label, out=sys.stderr, tty=None, clock=time.monotonic, quiet=False):
        self.label, self.out, self.clock, self.quiet = label, out, clock, quiet
        # PMSM_PROGRESS=none: no bar and no line for a build that succeeds (the example
        # outputs of the documentation, tools/doc_examples.py, are what the tools print)
        self.silent = os.environ.get("PMSM_PROGRESS") == "none"
        self.tty = out.isatty() if tty is None else tty
        self.t0 = clock()
        self.total = None
        self.done = 0
        self.shown_decile = -1

    def feed(self, line):
        """One line of the build's output; returns True when it was a counted step."""
        m = STATUS.match(line)
        if not m:
            return False
        done, total = int(m.group(1)), int(m.group(2))
        if done == 0:
            return False  # CMake's check of its globs before the build ("[0/2] Re-checking ...")
        if self.total is None:
            self.total = total
        if total != self.total or done < self.done:
            return False  # a build run inside a step, or a step's own output
        self.done = done
        self.show(m.group(3))
        return True

    def text(self, what=""):
        n, t = self.done, self.total or 0
        el = self.clock() - self.t0
        left = el / n * (t - n) if n > 0 else None
        width = 24
        fill = width * n // t if t else 0
        s = "%s [%s%s] %d/%d  %s elapsed" % (self.label, "#" * fill, "." * (width - fill), n, t,
                                             clock_text(el))
        if left is not None and n < t:
            s += ", ~%s left" % clock_text(left)
        if what:
            s += "  " + what[:60]
        return s

    def show(self, what=""):
        if self.silent:
            return
        if self.tty:
            self.out.write("\r\033[K" + self.text(what))
            self.out.flush()
            return
        decile = 10 * self.done // self.total if self.total else 0
        if decile > self.shown_decile:
            self.shown_decile = decile
            print(self.text(), file=self.out, flush=True)

    def end(self, ok):
        el = clock_text(self.clock() - self.t0)
        if self.silent and ok:
            return
        if self.tty:
            self.out.write("\r\033[K")
        if self.total is None:
            if ok and self.quiet:
                return  # nothing was built: nothing to say
            msg = "%s: up to date" % self.label if ok else "%s: failed" % self.label
        else:
            msg = "%s: %d steps in %s%s" % (self.label, self.done, el, "" if ok else ", FAILED")
        print(msg, file=self.out, flush=True)


def clock_text(s):
    s = int(round(s))
    return "%d:%02d" % (s // 60, s % 60)


def run_with_bar(argv, label, env=None, out=sys.stderr, log=None, quiet=False):
    """Run argv (a build), its status lines drawn as a bar; every line also goes to
    log (a file object, may be None); quiet: no line at all when nothing was built.
    Returns (exit status, the last 20 lines)."""
    e = dict(os.environ if env is None else env)
    e["NINJA_STATUS"] = "[%f/%t] "
    bar = Bar(label, out, quiet=quiet)
    tail = []
    try:
        p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             env=e, errors="replace")
    except OSError as ex:
        return 127, ["cannot run %s: %s" % (argv[0], ex)]
    for line in p.stdout:
        line = line.rstrip("\n")
        if log is not None:
            log.write(line + "\n")
        bar.feed(line)
        tail = (tail + [line])[-20:]
    rc = p.wait()
    bar.end(rc == 0)
    return rc, tail


def missing_tools(preset):
    return [t for t in NEEDS.get(preset, ["cmake", "ninja"]) if shutil.which(t) is None]


def missing_message(root, missing):
    return ("%s not installed: run 'sudo %s/tools/setup' (it installs what the project needs "
            "from Debian)" % (", ".join(missing), root))


def ensure_built(root, preset, target, artefact, out=sys.stderr, runs_with=()):
    """Configure build/<preset> if needed and build target; (True, None) when
    artefact exists afterwards, else (False, why). runs_with: the programs that will
    run it (qemu-system-arm), named with the build's tools when missing."""
    missing = missing_tools(preset) + [t for t in runs_with if shutil.which(t) is None]
    if missing:
        return False, missing_message(root, missing)
    bdir = os.path.join(root, "build", preset)
    logpath = os.path.join(bdir, "console-build.log")
    if not os.path.isfile(os.path.join(bdir, "build.ninja")):
        print("building %s: configuring build/%s (cmake --preset %s)" % (target, preset, preset),
              file=out, flush=True)
        r = subprocess.run(["cmake", "--preset", preset], cwd=root, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True)
        if r.returncode != 0:
            return False, "cmake --preset %s failed:\n%s" % (
                preset, "\n".join(r.stdout.splitlines()[-15:]))
    os.makedirs(bdir, exist_ok=True)
    with open(logpath, "w") as log:
        rc, tail = run_with_bar(["cmake", "--build", bdir, "--target", target],
                                "building %s" % target, out=out, log=log)
    if rc != 0:
        return False, "the build of %s failed (log: %s):\n%s" % (target, logpath, "\n".join(tail))
    if not os.path.isfile(artefact):
        return False, "the build of %s made no %s" % (target, artefact)
    return True, None


def main(argv):
    if len(argv) >= 3 and argv[1] == "--needs":
        # build_progress.py --needs PRESET [PROGRAM...]: exit 1 naming what is missing and
        # the one command that installs it (before a configure that would fail obscurely)
        missing = missing_tools(argv[2]) + [t for t in argv[3:] if shutil.which(t) is None]
        if missing:
            print(missing_message(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                  missing), file=sys.stderr)
            return 1
        return 0
    if len(argv) not in (3, 4):
        print("usage: build_progress.py BUILD_DIR TARGET [LABEL]\n"
              "       build_progress.py --needs PRESET [PROGRAM...]", file=sys.stderr)
        return 2
    bdir, target = argv[1], argv[2]
    label = argv[3] if len(argv) == 4 else "building %s" % target
    logpath = os.path.join(bdir, "%s-build.log" % target)
    with open(logpath, "w") as log:
        rc, tail = run_with_bar(["cmake", "--build", bdir, "--target", target, "-j2"], label,
                                log=log, quiet=True)
    if rc != 0:
        print("\n".join(tail), file=sys.stderr)
        print("%s failed (log: %s)" % (label, logpath), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
