"""Ctrl-C while runs start their workers (issue 34: Ctrl-C twice in a YADE batch on Dask printed
"Exception ignored in: <bound method Random.seed ...> SystemError: <built-in function
isinstance> returned a result with an exception set").

A worker is forked with a ``preexec_fn``, so its child runs Python between fork and exec (the
interpreter's at-fork hooks, such as random's reseeding, then the ``preexec_fn``), still in
the terminal's process group and with this process's Ctrl-C handler. On a loaded machine that
stretch lasts, and a Ctrl-C landing in it ran the handler in the child. The thread that forks
now holds SIGINT back, so that only rockyade's process takes a Ctrl-C, once.

Here every child is held 0.2 s between fork and exec (an at-fork hook that sleeps: what a
loaded machine does by chance), with a busy loop beside, and each of 20 batches on the Dask
executor and on threads is pressed twice within that stretch. (Two presses that come before
the main thread runs the handler count as one, Python's own signal handling: such a batch
is stopped once, not twice.)"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: 20 batches of runs that each start a worker of the engine-free driver; a thread presses
#: Ctrl-C (SIGINT to the process group, as a terminal does) twice while the first workers
#: are between fork and exec.
BATCHES = """
import functools, json, os, signal, sys, threading, time, tempfile
from pathlib import Path
from rockyade.io import warm_program
from rockyade.runner import Executor, run_jobs
from tests.processes import fake_program

folder = Path(tempfile.mkdtemp())
presses = []
trial = -1
forking = threading.local()

def press_twice():
    \"\"\"At a trial's first fork (its child now held): Ctrl-C, and again 0.08 s later.\"\"\"
    if not presses and getattr(forking, "trial", None) == trial:  # not a late fork of a stopped batch
        presses.append(threading.Timer(0.08, os.killpg, (0, signal.SIGINT)))
        os.killpg(0, signal.SIGINT)
        presses[0].start()

os.register_at_fork(after_in_child=lambda: time.sleep(0.2), after_in_parent=press_twice)

def job(i, of_trial):
    forking.trial = of_trial
    scene = folder / f"{of_trial}-{i}.json"
    scene.write_text(json.dumps({"name": str(i), "sleep_s": 0.1}))
    out, log = scene.with_suffix(".npz"), scene.with_suffix(".log")
    return warm_program.run_scene(fake_program(), scene, out, log, 60.0, warm=False)

hard = 0
for trial in range(20):
    presses.clear()
    outcome = run_jobs(range(4), functools.partial(job, of_trial=trial), executor=Executor(sys.argv[1], 2))
    presses[0].join()
    hard += outcome.hard
for thread in threading.enumerate():  # the runs abandoned after each second Ctrl-C
    if thread is not threading.main_thread() and not thread.daemon:
        thread.join(120)
print("hard", hard, flush=True)
"""


@pytest.mark.parametrize("executor", ["dask", "threads"])
def test_ctrl_c_twice_while_workers_start_runs_the_handler_once_and_raises_nothing(executor):
    if executor == "dask":
        pytest.importorskip("dask")
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])  # a loaded machine
    try:
        done = subprocess.run(
            [sys.executable, "-c", BATCHES, executor],
            cwd=ROOT,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=600,
            start_new_session=True,  # its own process group, as a command in a terminal
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
    finally:
        busy.kill()
        busy.wait()
    err = done.stderr
    assert done.returncode == 0 and done.stdout.startswith("hard "), (done.stdout, err)
    hard = int(done.stdout.split()[1])
    assert "Exception ignored" not in err and "Traceback" not in err, err
    # each press ran the handler once, in rockyade's process only (never in a child before exec)
    assert err.count("Ctrl-C: no new run starts") == 20, err
    assert err.count("Ctrl-C again: stopping the running runs now") == hard >= 10, err
