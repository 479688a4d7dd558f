"""One simulator run on a study worker (the part of tools/study_engine.py that
executes where the work is done).

Standard library only: the client sends this module to the workers by value
(cloudpickle), so a `dask worker` needs the project's simulator build, not this
repository's Python code. A task is self-contained: the simulator's build
identity, its arguments with every input file's content, and the names of the
outputs to bring back.

The run happens in a fresh scratch directory with relative paths only, so that
nothing of the worker's file system (temporary names, home directories) reaches
the simulator's messages: the same task gives the same bytes on every worker.
"""
import hashlib
import json
import os
import select
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import zlib

# Environment variable of a worker: simulators (paths, os.pathsep-separated) to
# look for a build among when the client's path does not hold it (a cluster
# whose machines install the project elsewhere).
SIM_ENV = "PMSM_STUDY_SIM"
STDERR_MAX = 65536  # bytes of the simulator's stderr kept (its tail)

_digests = {}  # path -> ((mtime_ns, size), sha256): a build is hashed once per worker


class MissingBuild(RuntimeError):
    """The worker has no simulator of the build the task names (not a result:
    the run is not stored and another worker, or a rerun, may do it)."""


def file_sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def build_digest(path):
    """sha256 of the simulator binary at path, None if there is none."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    stamp = (st.st_mtime_ns, st.st_size)
    got = _digests.get(path)
    if got is None or got[0] != stamp:
        got = (stamp, file_sha256(path))
        _digests[path] = got
    return got[1]


def find_sim(path, build):
    """The local simulator of this build: the client's path, else one of
    $PMSM_STUDY_SIM. Raises MissingBuild naming what was looked at."""
    tried = [path] + [p for p in os.environ.get(SIM_ENV, "").split(os.pathsep) if p]
    for p in tried:
        if build_digest(p) == build:
            return p
    raise MissingBuild(f"worker {worker_name()} has no simulator of build {build[:12]} "
                       f"(looked at {', '.join(tried)}; set {SIM_ENV} on the worker)")


def worker_name():
    if "distributed" in sys.modules:  # on a dask worker (never imported just to ask)
        try:
            return sys.modules["distributed"].get_worker().address
        except (AttributeError, ValueError):
            pass
    return f"{socket.gethostname()}:{os.getpid()}"


class Scratch:
    """The folder the runs of one dask task share: an input is written only when
    its content changes, a run's outputs and stderr are removed before it starts
    (the simulator sees exactly its own files; creating and removing a folder per
    run cost more than a short run's margin)."""

    def __init__(self):
        self.dir = tempfile.mkdtemp(prefix="pmsm-study-")
        self.have = {}  # relative path -> bytes written there

    def prepare(self, task):
        for rel, data in task["inputs"].items():
            if self.have.get(rel) != data:
                p = os.path.join(self.dir, rel)
                os.makedirs(os.path.dirname(p), exist_ok=True)
                with open(p, "wb") as f:
                    f.write(data)
                self.have[rel] = data
        for rel in list(task["outputs"].values()) + ["stderr.txt"]:
            p = os.path.join(self.dir, rel)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            if os.path.lexists(p):
                os.unlink(p)

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def wait_child(p, timeout_s):
    """Wait for the simulator; kill it after timeout_s. Returns (status, usage,
    timed out): os.wait4 gives the child's own CPU time (several runs share this
    process). A pidfd bounds the wait without a timer thread per run."""
    timed_out = False
    try:
        fd = os.pidfd_open(p.pid)
    except (AttributeError, OSError):
        fd = None
    if fd is not None:
        try:
            ready, _, _ = select.select([fd], [], [], timeout_s)
        finally:
            os.close(fd)
        if not ready:
            timed_out = True
            p.send_signal(signal.SIGKILL)
        _, status, usage = os.wait4(p.pid, 0)
    else:
        flag = []
        timer = threading.Timer(timeout_s, lambda: (flag.append(1), p.send_signal(signal.SIGKILL)))
        timer.start()
        try:
            _, status, usage = os.wait4(p.pid, 0)
        finally:
            timer.cancel()
        timed_out = bool(flag)
    p.returncode = os.waitstatus_to_exitcode(status)
    return status, usage, timed_out


def execute(task, scratch=None):
    """Run task (study_engine.Run.task()); returns the raw result: exit status,
    stderr, the outputs (zlib-compressed JSON {name: text or null}), the run's
    wall and CPU time (the simulator process's own) and the worker's name."""
    sim = find_sim(task["sim"], task["build"])
    own = scratch is None
    scratch = scratch or Scratch()
    try:
        scratch.prepare(task)
        d = scratch.dir
        err_path = os.path.join(d, "stderr.txt")
        t0 = time.perf_counter()
        with open(err_path, "wb") as err:
            p = subprocess.Popen([sim] + task["args"], cwd=d, stdin=subprocess.DEVNULL,
                                 stdout=subprocess.DEVNULL, stderr=err)
            _, usage, timed_out = wait_child(p, task["timeout_s"])
        wall = time.perf_counter() - t0
        with open(err_path, "rb") as f:
            stderr = f.read()[-STDERR_MAX:].decode("utf-8", "replace")
        outs = {}
        for name, rel in task["outputs"].items():
            try:
                with open(os.path.join(d, rel), "rb") as f:
                    outs[name] = f.read().decode("utf-8", "replace")
            except OSError:
                outs[name] = None
    finally:
        if own:
            scratch.close()
    return {"key": task["key"], "rc": p.returncode, "stderr": stderr, "timeout": timed_out,
            "outputs": zlib.compress(json.dumps(outs, sort_keys=True).encode(), 6),
            "wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime,
            "worker": worker_name()}


def execute_many(tasks):
    """execute() of each task in turn in one scratch folder: one dask task for
    several short runs, so that the scheduler's work per task is spread over them."""
    scratch = Scratch()
    try:
        return [execute(t, scratch) for t in tasks]
    finally:
        scratch.close()
