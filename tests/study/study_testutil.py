"""What the study engine's tests share (study_input_test.py, study_cluster_test.py):
how a study is watched, how many results its store holds, a free loopback port.

Every wait is on progress, not on a wall-clock budget: a study is given up only when
no new result (nor output) has come for STALL_S - a stuck study, whatever the
machine's speed or load; a slow one keeps its time.
"""
import os
import socket
import sqlite3
import time

# A study, a process's start or the scheduler's answer that shows no progress for this
# long is stuck. On two idle cores a result arrives every second or so and the cluster
# test takes about 30 s; on the shared machine loaded twenty-fold, a run took 2.5 s
# and the report after the last result about 20 s: the limit is ten times that, and
# it counts from the last sign of progress, not from the start.
STALL_S = 240


def stored(store):
    """Results in the store (runs.sqlite) so far: 0 before it exists or has its table."""
    if not store or not os.path.exists(store):
        return 0
    db = sqlite3.connect(store)
    try:
        return db.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    except sqlite3.OperationalError:
        return 0
    finally:
        db.close()


def _size(output):
    """Bytes written so far to output: a path (0 before it exists) or an open file."""
    if isinstance(output, str):
        return os.path.getsize(output) if os.path.exists(output) else 0
    return os.fstat(output.fileno()).st_size


def watch(proc, store, outputs=(), on_progress=None):
    """Wait for proc to end while it makes progress: a new result in store (None: no
    store) or one of outputs (paths or open files) growing. on_progress(results), if
    given, is called at every poll. Returns (exit status, or None if it was stuck for
    STALL_S - then proc is still running, the caller kills it; seconds it took)."""
    t0 = t_last = time.monotonic()
    last = None
    while proc.poll() is None:
        now = time.monotonic()
        n = stored(store)
        progress = (n,) + tuple(_size(o) for o in outputs)
        if progress != last:
            last, t_last = progress, now
        elif now - t_last > STALL_S:
            return None, now - t0
        if on_progress is not None:
            on_progress(n)
        time.sleep(0.05)
    return proc.returncode, time.monotonic() - t0


def free_port():
    """A TCP port on loopback that nothing listens on (at the time of the call)."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port
