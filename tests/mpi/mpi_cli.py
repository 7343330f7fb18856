# SPDX-License-Identifier: MIT
"""What the tests that run `domel run` under mpirun share: the environment
(OpenMPI refuses to start as root unless told; CI runs as root), the checks
that collect failures, and a run with a time limit (a hang fails, it does
not block)."""
import os
import subprocess
import time

env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_btl="self,vader")
failures = []


def mpi(mpiexec, np):
    """The launcher's words for np ranks on a machine with fewer cores."""
    return [mpiexec, "-np", str(np), "--oversubscribe"]


def launcher(mpiexec, np):
    """What goes before `domel run` for np ranks: nothing for one process."""
    return [] if np == 1 else mpi(mpiexec, np)


def mean_within_seed_spread(one, ranks):
    """The yardstick of the seed-over checks (silo_seeds_check.py,
    repose_check.py): the ranks' mean lies within the one-process seeds'
    spread of their mean. Returns (mean_one, mean_ranks, spread, whether)."""
    m1, mn = sum(one) / len(one), sum(ranks) / len(ranks)
    spread = max(one) - min(one)
    return m1, mn, spread, abs(mn - m1) <= spread


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what, flush=True)


def run(cmd, timeout=240):
    try:
        return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        check(False, "timed out (a hang): " + " ".join(cmd))
        return None


_part = {"name": None, "start": 0.0}


def part(name):
    """Start the script's part `name` (None: the end), printing how long the
    previous part took: what each part costs shows in the test's log."""
    now = time.monotonic()
    if _part["name"] is not None:
        print(f"[{_part['name']}: {now - _part['start']:.1f} s]", flush=True)
    _part["name"], _part["start"] = name, now
