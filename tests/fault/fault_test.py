#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Faults injected into `domel run` (ctest label fault; docs/reliability.md,
"Faults injected"). About 25 s on two cores.

usage: fault_test.py DOMEL SCENARIO WORKDIR [MPIEXEC PLUGIN]

SCENARIO is the settle example (2000 spheres falling into a box); PLUGIN a
valid plugin library (the ABI tests' good plugin), copied whole for some
ranks and cut short for others. Without MPIEXEC the parts on ranks are
skipped (a build without MPI).

1. SIGKILL at 3 random points (seeded: the delays are printed): the run,
   checkpointed every 0.004 s, is killed without warning some time after
   its first checkpoint (in the steps, or writing a frame or a checkpoint:
   wherever the delay lands); `--restart` from the folder's checkpoint then
   writes the uninterrupted run's probes.csv, frames, .pvd collections and
   last checkpoint (but for the time it was written) byte for byte, and leaves no temporary file of the
   killed process behind.
2. A full disk, as a file size limit (RLIMIT_FSIZE: a write past it fails
   with EFBIG; domel ignores SIGXFSZ, which would otherwise end it in the
   middle of the write), while a frame, a checkpoint and summary.json are
   written: each limit is chosen from the file sizes of an unlimited run so
   that the one file named is the first to exceed it. Each ends with exit 1,
   a message naming the file and the limit, and naming the last checkpoint
   as intact; that checkpoint is the same bytes as before, no temporary
   file is left, and a restart from it without the limit ends with the
   uninterrupted run's probes.csv and last frame.
3. On 3 ranks, one rank killed with SIGKILL ends the others within 30 s
   with the launcher's message naming the lost process, no hang; SIGTERM to
   one rank alone stops every rank at the same macro step with a
   checkpoint (exit 143), from which the run goes on.
4. On 3 ranks, a plugin folder ($DOMEL_PLUGIN_PATH) that holds the plugin
   whole for rank 0 and cut short (3,000 bytes: dlopen of it raised SIGBUS)
   for ranks 1 and 2: refused on every rank with exit 2, rank 0 naming what
   each rank loaded and the cut file, nothing written, within 30 s.
5. SIGTERM in the middle of a macro step that takes minutes (the fluidised
   bed's vans coupler told to take 10^6 fluid steps per exchange): the
   step does not end by itself within the 1 s grace, so the coupler, asked
   through the host (abi.h stop_requested), gives up; exit 143 within
   2.5 s, the message saying where it stopped, nothing of the step written.
"""
import json
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "mpi"))
import mpi_cli  # noqa: E402  (the checks and the environment the MPI scripts share)

domel, scenario, work = sys.argv[1], sys.argv[2], sys.argv[3]
mpiexec, plugin = (sys.argv[4], sys.argv[5]) if len(sys.argv) > 5 else (None, None)
check, failures, env = mpi_cli.check, mpi_cli.failures, mpi_cli.env


def write_scenario(doc, name):
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def run(cmd, limit=None, timeout=120):
    """`cmd` with a file size limit of `limit` bytes (None: none)."""
    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    try:
        return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout,
                              preexec_fn=limited if limit else None)
    except subprocess.TimeoutExpired:
        check(False, "timed out (a hang): " + " ".join(cmd))
        return None


def read(path):
    with open(path, "rb") as f:
        return f.read()


def leftovers(folder):
    return [f for f in os.listdir(folder) if re.search(r"\.tmp-\d+$", f)]


def comparable(path):
    """The file's bytes; of a checkpoint, all but the time it was written
    (its header's "written") and the checksum over it (the last 8 bytes)."""
    data = read(path)
    if path.endswith(".ckpt"):
        data = re.sub(rb'"written":"[^"]*"', b'"written":""', data[:-8], count=1)
    return data


def same_files(reference, folder, names, what):
    for name in names:
        a, b = os.path.join(reference, name), os.path.join(folder, name)
        check(os.path.exists(b) and comparable(a) == comparable(b), f"{what}: {name} is the uninterrupted run's bytes")


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
with open(scenario) as f:
    base = json.load(f)

# 1. SIGKILL at random points, then a restart
mpi_cli.part("1. SIGKILL and restart")
doc = json.loads(json.dumps(base))
doc["run"].update(duration=0.06, checkpoint_interval=0.004)
doc["output"].update(vtk_interval=0.01, probe_interval=0.001)
killed_scenario = write_scenario(doc, "killed")
reference = os.path.join(work, "uninterrupted")
start = time.monotonic()
r = run([domel, "run", killed_scenario, "--out", reference, "--quiet", "--threads", "1"])
wall = time.monotonic() - start
ran = r is not None and r.returncode == 0
check(ran, "the uninterrupted run: " + (r.stderr[-400:] if r else ""))
compared = sorted(f for f in os.listdir(reference)
                  if f.endswith((".vtp", ".pvd", ".csv")) or f == "checkpoint.ckpt") if ran else []
rng = random.Random(20261207)
for k in range(3):
    folder = os.path.join(work, f"killed_{k}")
    delay = rng.uniform(0.0, 0.6) * wall
    for attempt in range(4):  # a run that ends before its kill (a faster moment of the host) is killed sooner
        shutil.rmtree(folder, ignore_errors=True)
        proc = subprocess.Popen([domel, "run", killed_scenario, "--out", folder, "--quiet", "--threads", "1"],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < deadline and \
                not os.path.exists(os.path.join(folder, "checkpoint.ckpt")):
            time.sleep(0.001)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=30)
        if proc.returncode == -signal.SIGKILL:
            break
        delay /= 2
    if proc.returncode != -signal.SIGKILL:
        check(False, f"kill {k}: the run ended by itself ({proc.returncode}) before every kill")
        continue
    restart = run([domel, "run", killed_scenario, "--out", folder, "--threads", "1",
                   "--restart", os.path.join(folder, "checkpoint.ckpt")])
    m = re.search(r"restart from .*: t = ([0-9.e+-]+) s", restart.stderr if restart else "")
    print(f"kill {k}: SIGKILL {delay:.3f} s after the first checkpoint (runs take {wall:.2f} s), restarted from "
          f"t = {m.group(1) if m else '?'} s", flush=True)
    check(restart is not None and restart.returncode == 0, f"kill {k}: the restart ran: " +
          (restart.stderr[-600:] if restart else ""))
    if restart is not None and restart.returncode == 0:
        same_files(reference, folder, compared, f"kill {k}")
        check(not leftovers(folder), f"kill {k}: no temporary file left: {leftovers(folder)}")

# 2. a full disk (a file size limit) during a frame, a checkpoint and summary.json
mpi_cli.part("2. full disk")
doc = json.loads(json.dumps(base))
doc["run"].update(duration=0.03, checkpoint_interval=0.01)
doc["output"].update(vtk_interval=0.005, probe_interval=0.001)
full_scenario = write_scenario(doc, "full")
doc["output"]["vtk_interval"] = 0
doc["run"]["checkpoint_interval"] = 0  # the restart writes probe rows and summary.json alone (allowed changes)
summary_scenario = write_scenario(doc, "full_summary_only")
whole, start_folder = os.path.join(work, "full_whole"), os.path.join(work, "full_start")
r1 = run([domel, "run", full_scenario, "--out", whole, "--quiet"])
r2 = run([domel, "run", full_scenario, "--out", start_folder, "--quiet", "--max-steps", "1000"])
ran = all(r is not None and r.returncode == 0 for r in (r1, r2))
check(ran, "the unlimited runs ran")
if ran:
    ck = read(os.path.join(start_folder, "checkpoint.ckpt"))
    frames_after = [os.path.getsize(os.path.join(whole, f)) for f in os.listdir(whole)
                    if re.match(r"particles_\d+\.vtp$", f) and int(f[10:16]) >= 2]
    probes_1200 = sum(len(line) for line in read(os.path.join(whole, "probes.csv")).splitlines(keepends=True)
                      if not line[:1].isdigit() or float(line.split(b",")[0]) <= 0.0120000001)
    summary_size = os.path.getsize(os.path.join(start_folder, "summary.json"))
    small = max(os.path.getsize(os.path.join(whole, f)) for f in ("probes.csv", "domel_manifest.txt", "walls.pvd",
                                                                  "particles.pvd"))
    restart_frame = os.path.getsize(os.path.join(start_folder, "particles_000002.vtp"))
    cases = [  # (what, the file that fails, the limit, the scenario, steps)
        ("a frame", "particles_000002.vtp", (small + restart_frame) // 2, full_scenario, 3000),
        ("a checkpoint", "checkpoint.ckpt", (max(frames_after) + len(ck)) // 2, full_scenario, 3000),
        ("summary.json", "summary.json", (probes_1200 + summary_size) // 2, summary_scenario, 1200),
    ]
    check(small < cases[0][2] < restart_frame, f"the frame's limit lies between {small} and {restart_frame} B")
    check(max(frames_after) < cases[1][2] < len(ck), "the checkpoint's limit lies between the largest frame and it")
    check(probes_1200 + 600 < cases[2][2] < summary_size, f"summary.json's limit ({cases[2][2]} B) lies between "
                                                          f"probes.csv ({probes_1200} B) and it ({summary_size} B)")
    for what, name, limit, scen, steps in cases:
        folder = os.path.join(work, "full_" + name.split(".")[0].split("_")[0])
        shutil.copytree(start_folder, folder)
        r = run([domel, "run", scen, "--out", folder, "--quiet", "--max-steps", str(steps),
                 "--restart", os.path.join(folder, "checkpoint.ckpt")], limit=limit)
        print(f"full disk during {what} (limit {limit} B): exit {r.returncode if r else None}: "
              f"{r.stderr.strip() if r else ''}", flush=True)
        if r is None:
            continue
        check(r.returncode == 1, f"{what}: exit status 1 (found {r.returncode})")
        check(f"cannot write file '{os.path.join(folder, name)}'" in r.stderr and "file size limit" in r.stderr,
              f"{what}: the message names {name} and the limit")
        check("the last checkpoint, of t = 0.01 s, is intact" in r.stderr and "--restart" in r.stderr,
              f"{what}: the message names the intact checkpoint")
        check(read(os.path.join(folder, "checkpoint.ckpt")) == ck, f"{what}: the checkpoint is the same bytes")
        check(not leftovers(folder), f"{what}: no temporary file left: {leftovers(folder)}")
        again = run([domel, "run", full_scenario, "--out", folder, "--quiet", "--restart",
                     os.path.join(folder, "checkpoint.ckpt")])
        check(again is not None and again.returncode == 0, f"{what}: the restart without the limit ran")
        if again is not None and again.returncode == 0:
            same_files(whole, folder, ["probes.csv", "particles_000006.vtp"], f"{what}, restarted")


def rank_pids(folder, ranks):
    """The pids of the `domel run` processes writing `folder`, by MPI rank."""
    found = {}
    deadline = time.monotonic() + 30
    while len(found) < ranks and time.monotonic() < deadline:
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                cmd = read(f"/proc/{pid}/cmdline").split(b"\0")
                environ = read(f"/proc/{pid}/environ").split(b"\0")
            except OSError:
                continue
            if folder.encode() not in cmd or os.path.basename(cmd[0]) != b"domel":
                continue
            for var in environ:
                if var.startswith(b"OMPI_COMM_WORLD_RANK="):
                    found[int(var.split(b"=")[1])] = int(pid)
        time.sleep(0.05)
    return found


def wait_for(path, seconds=60):
    deadline = time.monotonic() + seconds
    while not os.path.exists(path) and time.monotonic() < deadline:
        time.sleep(0.05)
    return os.path.exists(path)


if mpiexec:
    # 3. a rank lost on 3 ranks
    mpi_cli.part("3. a rank lost on 3 ranks")
    doc = json.loads(json.dumps(base))
    doc["run"].update(duration=5.0, checkpoint_interval=1.0)
    doc["output"].update(vtk_interval=0.005)
    long_scenario = write_scenario(doc, "ranks_long")
    for sig, what in ((signal.SIGKILL, "killed"), (signal.SIGTERM, "asked to stop")):
        folder = os.path.join(work, "ranks_" + what.split()[0])
        proc = subprocess.Popen(mpi_cli.mpi(mpiexec, 3) + [domel, "run", long_scenario, "--out", folder, "--quiet"],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        pids = rank_pids(folder, 3)
        check(wait_for(os.path.join(folder, "particles_000001.vtp")) and 1 in pids, f"rank 1 {what}: the run started")
        if 1 not in pids:
            proc.kill()
            continue
        os.kill(pids[1], sig)
        start = time.monotonic()
        try:
            out, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            check(False, f"rank 1 {what}: the other ranks did not end within 30 s (a hang)")
            continue
        took = time.monotonic() - start
        print(f"rank 1 of 3 {what}: every rank ended {took:.2f} s later, exit {proc.returncode}; the last lines: "
              f"{err.strip().splitlines()[-3:]}", flush=True)
        check(proc.returncode != 0, f"rank 1 {what}: a non-zero exit")
        if sig == signal.SIGKILL:
            check("rank 1" in err and ("signal 9" in err or "Killed" in err),
                  "the launcher names the lost rank: " + err[-600:])
        else:
            check(proc.returncode == 143, f"SIGTERM to rank 1: exit 143 (found {proc.returncode})")
            summary = json.load(open(os.path.join(folder, "summary.json")))
            check(summary["status"] == "interrupted" and summary.get("checkpoint") == "checkpoint.ckpt",
                  "SIGTERM to rank 1: summary.json says interrupted, with its checkpoint")
            check(err.count("interrupted at t =") == 1 and "MPI_ABORT" not in err,
                  "SIGTERM to rank 1: every rank ended cleanly: " + err[-400:])
            r = run(mpi_cli.mpi(mpiexec, 3) + [domel, "run", long_scenario, "--out", folder, "--quiet", "--max-steps",
                                               str(summary["steps"] + 50), "--restart",
                                               os.path.join(folder, "checkpoint.ckpt")])
            check(r is not None and r.returncode == 0, "SIGTERM to rank 1: the run goes on from its checkpoint")

    # 4. a plugin cut short in one rank's view
    mpi_cli.part("4. a plugin cut short on some ranks")
    whole_dir, cut_dir = os.path.join(work, "plugins_whole"), os.path.join(work, "plugins_cut")
    os.makedirs(whole_dir)
    os.makedirs(cut_dir)
    shutil.copy(plugin, whole_dir)
    with open(plugin, "rb") as f, open(os.path.join(cut_dir, os.path.basename(plugin)), "wb") as g:
        g.write(f.read(3000))
    folder = os.path.join(work, "plugins_refused")
    cmd = [domel, "run", scenario, "--out", folder, "--quiet"]
    start = time.monotonic()
    r = run([mpiexec, "--oversubscribe", "-np", "1", "-x", "DOMEL_PLUGIN_PATH=" + whole_dir] + cmd +
            [":", "-np", "2", "-x", "DOMEL_PLUGIN_PATH=" + cut_dir] + cmd, timeout=60)
    if r is not None:
        print(f"plugin cut short on ranks 1 and 2: exit {r.returncode} after {time.monotonic() - start:.2f} s:\n"
              f"{r.stderr[:900]}", flush=True)
        check(r.returncode == 2, f"the run is refused with exit 2 (found {r.returncode})")
        check("do not load the same plugins" in r.stderr and "ranks 1, 2" in r.stderr and "cut short" in r.stderr,
              "rank 0 names what differs and the cut file")
        check(r.stderr.count("nothing was run") == 1 and "MPI_ABORT" not in r.stderr, "said once, no abort")
        check(not os.path.exists(os.path.join(folder, "summary.json")), "nothing written")

# 5. a stop request inside a macro step that does not end by itself
mpi_cli.part("5. a stop inside a long step")
bed = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(scenario))), "fluid", "bed", "a4.json")
with open(bed) as f:
    doc = json.load(f)
doc["fluid"]["substeps"] = 1000000  # the first exchange alone takes minutes
doc["run"]["checkpoint_interval"] = 0.01
slow_scenario = write_scenario(doc, "bed_slow")
folder = os.path.join(work, "bed_slow")
proc = subprocess.Popen([domel, "run", slow_scenario, "--out", folder, "--quiet"], env=env,
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
started = wait_for(os.path.join(folder, "domel_manifest.txt"))
time.sleep(1.0)  # set-up done, the first exchange under way
proc.send_signal(signal.SIGTERM)
start = time.monotonic()
try:
    out, err = proc.communicate(timeout=30)
    took = time.monotonic() - start
    print(f"SIGTERM in the middle of a fluid exchange of 10^6 fluid steps: ended {took:.2f} s later, exit "
          f"{proc.returncode}: {err.strip().splitlines()[-2:]}", flush=True)
    check(started and proc.returncode == 143, f"exit 143 (found {proc.returncode})")
    check(took < 1.0 + 1.5, f"ended within the 1 s grace and 1.5 s of work (took {took:.2f} s)")
    check("interrupted in the middle of a macro step" in err and "vans: stopped on request after" in err and
          "no checkpoint was written" in err, "the message says where the step stopped: " + err[-500:])
    check(not os.path.exists(os.path.join(folder, "summary.json")) and not leftovers(folder),
          "nothing of the unfinished step written")
except subprocess.TimeoutExpired:
    proc.kill()
    check(False, "SIGTERM in the middle of a long fluid exchange: no end within 30 s")

mpi_cli.part(None)
if failures:
    print(f"{len(failures)} failure(s)")
    sys.exit(1)
print("all fault checks passed")
