#!/usr/bin/env python3
"""Run the S1 'settle' throughput benchmark: domel against LIGGGHTS, interleaved, on this machine, now.

What is measured (see docs/benchmarks.md and ../shared/peers/RESULTS.md):
  S1 = a simple-cubic lattice column of N spheres compacting under gravity in a box (Hertz-Mindlin,
  d = 2.8 mm, dt = 1e-5 s, skin 0.5 d). Each run does 2000 untimed steps from the lattice, then 2000 timed
  steps; the number is particle-steps per wall-clock second of the timed steps only:
    domel:    `domel run bench/scenarios/s1_settle_<N>.json --time-after 2000` -> summary.json "timed_window"
    LIGGGHTS: the peers' deck (settle.in, RF none) -> N_actual * 2000 / 'Loop time' of the run after the
              BENCHMARK_TIMED_RUN_START marker (exactly as ../shared/peers/run_peers.sh computes it).
  Both codes run serially (one process, OMP_NUM_THREADS=1), or with --ranks R both on R MPI ranks
  (`mpirun -np R`; LIGGGHTS with `processors 1 1 R`, its deck's pz), and domel also as one process on R
  threads (code domel_<R>t) for the ranks-against-threads comparison. For each N the runs alternate
  domel, LIGGGHTS, domel, LIGGGHTS, ... so that slow drifts of the machine's load hit both codes alike.

Recorded per run (CSV in bench/results/s1_<timestamp>.csv): code, N requested/actual, rep, timed wall,
particle-steps/s, whole-process wall and CPU seconds, 1-min load average at start and end, the CPU seconds of
the timed steps (LIGGGHTS: the deck's cpusec.sh lines; domel: sampled from /proc/<pid>/stat, the CPU the
process used in its last timed_wall_s seconds, since the timed steps end the run) and particle-steps per
CPU-second, and as a check that both codes did the same physics the mean particle-particle contacts per
particle at the end (domel: 2 * contacts / particles from summary.json; LIGGGHTS: CONTACTINFO zmean), the
translational kinetic energy at step 4000 and the neighbour-list builds.
The printed tables give medians [min-max] per code and the domel/LIGGGHTS ratio of the medians, per
wall-clock second (the benchmark number) and per CPU-second (the cross-check when the machine is loaded).

Usage:
    python3 bench/run_s1.py                       # N = 10000 50000, 3 reps, with LIGGGHTS if on PATH
    python3 bench/run_s1.py --sizes 10000 50000 --reps 3 --with-200k
    python3 bench/run_s1.py --quick               # N = 10000, 1 rep (smoke test)
    python3 bench/run_s1.py --deck bed --threads 1 2   # the dense settled bed (bench/make_bed.py, docs/benchmarks.md)
    python3 bench/run_s1.py --no-peer             # domel only
    python3 bench/run_s1.py --ranks 2 --sizes 50000 200000   # both codes on 2 MPI ranks (+ domel 1 rank x 2 threads)
    python3 bench/run_s1.py --report bench/results/s1_<timestamp>.csv   # re-print the tables of a run
Exit status: 0 when every run succeeded, 1 when any failed (all other runs are still done), 2 on bad usage.
Only the Python standard library is used. The machine's load matters: on a shared machine, read the load
column and the per-CPU-second table before trusting a number.
"""

import argparse
import csv
import json
import os
import platform
import re
import resource
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import make_s1  # noqa: E402  (same folder)
import make_bed  # noqa: E402

# The deck being run: "s1" (S1/S2, the peers' settle.in) or "bed" (the dense settled bed of make_bed.py).
DECK = {"name": "s1", "bed_dir": None}
# MPI ranks per run (--ranks); 1: one process
RANKS = {"n": 1}


def mpirun(ranks):
    """The launcher prefix for `ranks` processes (none for one)."""
    if ranks <= 1:
        return []
    return [shutil.which("mpirun") or "mpirun", "-np", str(ranks)]

NSETTLE = make_s1.NSETTLE
NRUN = make_s1.NRUN

CSV_FIELDS = [
    "timestamp", "code", "N_requested", "N_actual", "rep", "ok", "timed_steps", "timed_wall_s",
    "particle_steps_per_s", "process_wall_s", "process_cpu_s", "timed_cpu_s", "particle_steps_per_cpu_s",
    "load1_start", "load1_end", "mean_contacts_per_particle", "ke_translational_final_J", "neighbor_builds_total",
    "peak_rss_bytes", "history_bytes", "error", "log",
]


def default_domel():
    for rel in ("build-bench/bin/domel", "build/bin/domel"):
        p = os.path.join(ROOT, rel)
        if os.access(p, os.X_OK):
            return p
    return shutil.which("domel")


def default_peers():
    for p in (os.path.join(ROOT, "..", "shared", "peers"), "/work/shared/peers"):
        if os.path.isfile(os.path.join(p, "liggghts", "settle.in")):
            return os.path.abspath(p)
    return None


def machine_info():
    model = "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"host": socket.gethostname(), "nproc": os.cpu_count(), "cpu": model,
            "python": platform.python_version()}


def load1():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def proc_cpu_seconds(pid, tck=os.sysconf("SC_CLK_TCK")):
    """utime + stime of a running process from /proc (clock-tick resolution), or None."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / tck
    except (OSError, IndexError, ValueError):
        return None


def run_timed(cmd, cwd, stdout_path, timeout, env, sample_s=0.02):
    """Run cmd; return (returncode, wall seconds, CPU seconds user+sys of the child, samples).

    samples: [(seconds since start, CPU seconds of the child)] read from /proc every sample_s, ending with
    (wall at exit, total CPU from getrusage), so that the CPU time of a window that ends when the process
    ends (domel's timed steps) can be read off: see cpu_in_last().
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    samples = []
    with open(stdout_path, "w") as out:
        try:
            proc = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env)
        except OSError as exc:
            out.write("could not start %s: %s\n" % (cmd[0], exc))
            return 127, 0.0, 0.0, samples
        killed = False
        while proc.poll() is None:
            now = time.monotonic() - t0
            if now > timeout:
                proc.kill()
                proc.wait()
                killed = True
                break
            c = proc_cpu_seconds(proc.pid)
            if c is not None:
                samples.append((now, c))
            time.sleep(sample_s)
        rc = 124 if killed else proc.returncode
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    samples.append((wall, cpu))
    return rc, wall, cpu, samples


def cpu_in_last(samples, window_s):
    """CPU seconds used in the last window_s of the run (linear interpolation between samples)."""
    if len(samples) < 2:
        return None
    t_end, c_end = samples[-1]
    t0 = t_end - window_s
    if t0 <= samples[0][0]:
        return None
    for (ta, ca), (tb, cb) in zip(samples, samples[1:]):
        if ta <= t0 <= tb:
            c0 = ca + (cb - ca) * ((t0 - ta) / (tb - ta) if tb > ta else 0.0)
            return c_end - c0
    return None


def scenario_file(n, workdir, rolling="none"):
    """The committed bench/scenarios file for N when it exists and matches make_s1.py, else a fresh one."""
    fresh = make_s1.scenario(n, rolling, DECK.get("plugins"))
    committed = os.path.join(HERE, "scenarios", fresh["name"] + ".json")
    if os.path.isfile(committed):
        with open(committed) as f:
            if json.load(f) == fresh:
                return committed
        print("warning: %s differs from make_s1.py's output; using a regenerated copy" % committed,
              file=sys.stderr)
    path = os.path.join(workdir, fresh["name"] + ".json")
    with open(path, "w") as f:
        f.write(make_s1.dumps(fresh) + "\n")
    return path


def steps():
    """(untimed, timed) steps of the deck being run."""
    return (make_bed.NSETTLE, make_bed.NRUN) if DECK["name"] == "bed" else (NSETTLE, NRUN)


def expected_particles(n):
    """The particle count domel should report for requested N on the deck being run."""
    nx, ny, nz = make_s1.lattice_dims(n)
    return n if DECK["name"] == "bed" else nx * ny * nz


def deck_scenario(n, workdir, rolling="none"):
    """Path of the domel scenario of the deck being run (DECK) for N and a rolling model (a bed must be prepared)."""
    return (make_bed.scenario_file(n, DECK["bed_dir"], rolling) if DECK["name"] == "bed"
            else scenario_file(n, workdir, rolling))


def summary_final(s):
    """End-of-run physics from a parsed summary.json: contacts per particle, translational KE, list builds, history."""
    res = {}
    sds = s.get("subdomains") or []
    if sds:
        sd = sds[0]
        fin = sd.get("final", {})
        if "contacts" in fin and sd.get("particles"):
            res["mean_contacts_per_particle"] = 2.0 * fin["contacts"] / sd["particles"]
        res["ke_translational_final_J"] = fin.get("ke_translational_J")
        res["neighbor_builds_total"] = sd.get("neighbor_list_builds")
        res["history_bytes"] = (sd.get("memory_bytes") or {}).get("contact_history")
    return res


def build_epsd_example(domel, workdir):
    """libdomel_rolling_epsd.so built as a third party builds it: the domel build tree of the --domel binary
    installed into <workdir>/epsd-prefix, examples/third_party_rolling configured against that prefix only."""
    build = os.path.dirname(os.path.dirname(os.path.realpath(domel)))
    if not os.path.isfile(os.path.join(build, "CMakeCache.txt")):
        sys.exit("run_s1.py: --rolling epsd2_plugin: %s is not in a CMake build tree (no %s); build the example "
                 "(examples/third_party_rolling/README.md) and pass --epsd-library" %
                 (domel, os.path.join(build, "CMakeCache.txt")))
    prefix, out = os.path.join(workdir, "epsd-prefix"), os.path.join(workdir, "epsd-build")
    project = os.path.join(os.path.dirname(HERE), "examples", "third_party_rolling")
    for cmd in (["cmake", "--install", build, "--prefix", prefix],
                ["cmake", "-S", project, "-B", out, "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_PREFIX_PATH=" + prefix],
                ["cmake", "--build", out]):
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode != 0:
            sys.exit("run_s1.py: building the epsd example failed: %s\n%s" % (" ".join(cmd), r.stdout))
    return os.path.join(out, "libdomel_rolling_epsd.so")


def run_domel(domel, n, rep, workdir, timeout, env, threads=1, rolling="none", ranks=1):
    expected = expected_particles(n)
    nsettle, nrun = steps()
    scen = deck_scenario(n, workdir, rolling)
    code = "domel" if threads == 1 else "domel_%dt" % threads
    outdir = os.path.join(workdir, "%s_N%d_r%d" % (code, n, rep))
    log = outdir + ".screen"
    row = {"code": code, "N_requested": n, "rep": rep, "log": log}
    row["load1_start"] = load1()
    shutil.rmtree(outdir, ignore_errors=True)  # a fresh folder (domel refuses one with an earlier run's output)
    rc, wall, cpu, samples = run_timed(mpirun(ranks) + [domel, "run", scen, "--out", outdir, "--quiet",
                               "--time-after", str(nsettle), "--threads", str(threads)], workdir, log, timeout, env)
    row.update(load1_end=load1(), process_wall_s=wall, process_cpu_s=cpu)
    summary_path = os.path.join(outdir, "summary.json")
    if rc != 0 or not os.path.isfile(summary_path):
        row.update(ok=0, error="domel exit %d (see %s)" % (rc, log))
        return row
    with open(summary_path) as f:
        s = json.load(f)
    tw = s.get("timed_window")
    if not tw:
        row.update(ok=0, error="summary.json has no timed_window")
        return row
    row.update(N_actual=s.get("particles"), timed_steps=tw.get("steps"), timed_wall_s=tw.get("wall_time_s"),
               particle_steps_per_s=tw.get("particle_steps_per_s"), peak_rss_bytes=s.get("peak_rss_bytes"))
    row.update(summary_final(s))
    # domel has no CPU clock of its own around the timed steps: they are the last steps of the process, so
    # take the CPU time the process used in its last timed_wall_s seconds (sampled from /proc every 20 ms;
    # includes the few ms of summary writing and exit)
    tcpu = cpu_in_last(samples, row["timed_wall_s"] or 0.0) if ranks == 1 else None  # mpirun's own CPU, not the ranks'
    if tcpu:
        row["timed_cpu_s"] = tcpu
        row["particle_steps_per_cpu_s"] = row["N_actual"] * row["timed_steps"] / tcpu
    if row["N_actual"] != expected:
        row.update(ok=0, error="N_actual %s != %d" % (row["N_actual"], expected))
    elif row["timed_steps"] != nrun:
        row.update(ok=0, error="timed window has %s steps, expected %d" % (row["timed_steps"], nrun))
    else:
        row["ok"] = 1
    return row


def parse_liggghts(text):
    """Numbers from a LIGGGHTS settle.in screen: as in ../shared/peers/run_peers.sh."""
    res = {}
    m = re.search(r"BENCHINFO code=\S+ N=(\d+)", text)
    if m:
        res["N_actual"] = int(m.group(1))
    marker = text.find("BENCHMARK_TIMED_RUN_START")
    if marker >= 0:
        m = re.search(r"^Loop time of (\S+) on \d+ procs for (\d+) steps", text[marker:], re.M)
        if m:
            res["timed_wall_s"] = float(m.group(1))
            res["timed_steps"] = int(m.group(2))
    # thermo rows 'step atoms ke x' (thermo_modify norm no: total translational KE); keep the last at the end
    final = sum(steps())
    for m in re.finditer(r"^\s*(\d+)\s+\d+\s+([-+0-9.eE]+)\s+[-+0-9.eE]+\s*$", text, re.M):
        if int(m.group(1)) == final:
            res["ke_translational_final_J"] = float(m.group(2))
    m = re.search(r"CONTACTINFO zmean=(\S+)", text)
    if m:
        res["mean_contacts_per_particle"] = float(m.group(1))
    # 'shell' output can land mid-line in LIGGGHTS' buffered screen (RESULTS.md, deck problem 7)
    cpus = [float(v) for v in re.findall(r"CPUSECONDS ([0-9.]+)", text)]
    if len(cpus) >= 2:
        res["timed_cpu_s"] = cpus[1] - cpus[0]
    builds = [int(v) for v in re.findall(r"^Neighbor list builds = (\d+)", text, re.M)]
    if builds:
        res["neighbor_builds_total"] = sum(builds)
    return res


def run_liggghts(liggghts, deckdir, n, rep, workdir, timeout, env, rolling="none"):
    tag = "liggghts_N%d_r%d" % (n, rep)
    log, screen = os.path.join(workdir, tag + ".log"), os.path.join(workdir, tag + ".screen")
    row = {"code": "liggghts", "N_requested": n, "rep": rep, "log": screen}
    nsettle, nrun = steps()
    if DECK["name"] == "bed":
        cmd = [liggghts, "-in", "bed.in", "-var", "data", make_bed.paths(DECK["bed_dir"], n)["data"]]
    else:
        cmd = [liggghts, "-in", "settle.in", "-var", "N", str(n)]
    if RANKS["n"] > 1:
        cmd = mpirun(RANKS["n"]) + cmd + ["-var", "pz", str(RANKS["n"])]
    cmd += ["-var", "nsettle", str(nsettle), "-var", "nrun", str(nrun), "-var", "RF", make_s1.PEER_RF.get(rolling, rolling), "-log", log]
    if shutil.which("stdbuf"):  # LIGGGHTS dies silently when stdout is a file (RESULTS.md, problem 2)
        cmd = ["stdbuf", "-oL"] + cmd
    row["load1_start"] = load1()
    rc, wall, cpu, _ = run_timed(cmd, deckdir, screen, timeout, env)
    row.update(load1_end=load1(), process_wall_s=wall, process_cpu_s=cpu)
    with open(screen, errors="replace") as f:
        row.update(parse_liggghts(f.read()))
    if rc != 0 or "timed_wall_s" not in row or "N_actual" not in row:
        row.update(ok=0, error="liggghts exit %d, timed Loop time %s (see %s)"
                   % (rc, "found" if "timed_wall_s" in row else "missing", screen))
        return row
    row["particle_steps_per_s"] = row["N_actual"] * row["timed_steps"] / row["timed_wall_s"]
    if row.get("timed_cpu_s"):
        row["particle_steps_per_cpu_s"] = row["N_actual"] * row["timed_steps"] / row["timed_cpu_s"]
    row["ok"] = 1
    return row


def stats(values):
    v = [x for x in values if isinstance(x, (int, float))]
    if not v:
        return None
    return statistics.median(v), min(v), max(v)


def fmt_rate(st):
    if st is None:
        return "-"
    return "%.2e [%.2e-%.2e]" % st


def print_tables(rows, sizes, have_peer, deck="S1 settle"):
    print()
    head = ["N", "domel median [min-max]", "LIGGGHTS median [min-max]", "ratio domel/LIGGGHTS", "load"]
    lines = []
    for n in sizes:
        mine = [r for r in rows if r["N_requested"] == n]
        nact = next((r.get("N_actual") for r in mine if r.get("N_actual")), n)
        d = stats([r.get("particle_steps_per_s") for r in mine if r["code"] == "domel" and r.get("ok")])
        p = stats([r.get("particle_steps_per_s") for r in mine if r["code"] == "liggghts" and r.get("ok")])
        ratio = "%.2f" % (d[0] / p[0]) if d and p else "-"
        loads = [r["load1_start"] for r in mine if isinstance(r.get("load1_start"), float)]
        load = "%.2f-%.2f" % (min(loads), max(loads)) if loads else "-"
        nd = sum(1 for r in mine if r["code"] == "domel" and r.get("ok"))
        np_ = sum(1 for r in mine if r["code"] == "liggghts" and r.get("ok"))
        lines.append([str(nact), fmt_rate(d) + " (%d)" % nd,
                      (fmt_rate(p) + " (%d)" % np_) if have_peer else "not run", ratio, load])
    print(deck + ", timed particle-steps/s (%d steps after %d untimed); (runs); " % (steps()[1], steps()[0]) +
          "load = 1-min load average at the start of the runs")
    print_md(head, lines)

    threaded = sorted({r["code"] for r in rows if r["code"].startswith("domel_")})
    if threaded:
        print()
        if RANKS["n"] > 1:
            print("domel as one process with worker threads against both codes on %d ranks (wall-clock, timed "
                  "steps); speed-up = over domel on %d ranks x 1 thread in the same invocation" % (RANKS["n"], RANKS["n"]))
        else:
            print("domel with worker threads (wall-clock, timed steps) against serial LIGGGHTS; speed-up = over "
                  "domel on 1 thread in the same invocation")
        tl = []
        for code in threaded:
            for n in sizes:
                mine = [r for r in rows if r["N_requested"] == n]
                dt_ = stats([r.get("particle_steps_per_s") for r in mine if r["code"] == code and r.get("ok")])
                d1 = stats([r.get("particle_steps_per_s") for r in mine if r["code"] == "domel" and r.get("ok")])
                p = stats([r.get("particle_steps_per_s") for r in mine if r["code"] == "liggghts" and r.get("ok")])
                nact = next((r.get("N_actual") for r in mine if r.get("N_actual")), n)
                tl.append([code, str(nact), fmt_rate(dt_), "%.2f" % (dt_[0] / d1[0]) if dt_ and d1 else "-",
                           "%.2f" % (dt_[0] / p[0]) if dt_ and p else "-"])
        print_md(["domel", "N", "median [min-max]", "speed-up",
                  "ratio domel/LIGGGHTS " + ("on %d ranks" % RANKS["n"] if RANKS["n"] > 1 else "serial")], tl)

    mem = []
    for n in sizes:
        mine = [r for r in rows if r["N_requested"] == n and r["code"] == "domel" and r.get("ok")]
        rss = stats([r.get("peak_rss_bytes") for r in mine])
        hist = stats([float(r["history_bytes"]) for r in mine if r.get("history_bytes") not in (None, "")])
        nact = next((r.get("N_actual") for r in mine if r.get("N_actual")), None)
        if rss and nact:
            mem.append((float(nact), rss[0], hist[0] if hist else None))
    if mem:
        print()
        print("domel peak resident memory (1 thread, median over runs; whole process: libraries, VTK, the pair list and "
              "its contact history included); bytes per particle = slope between the sizes. Contact history = the "
              "history rows of the pair and wall lists at the end of the run (summary.json memory_bytes)")
        ml = [[str(int(nn)), "%.1f MB" % (r / 1e6), "%.0f" % (r / nn), "%.1f MB" % (h / 1e6) if h else "-"]
              for nn, r, h in mem]
        print_md(["N", "peak RSS", "RSS / N (bytes)", "contact history"], ml)
        if len(mem) >= 2:
            (n1, r1, h1), (n2, r2, h2) = mem[0], mem[-1]
            if n2 != n1:
                marginal = (r2 - r1) / (n2 - n1)
                print("marginal memory per particle between N = %d and %d: %.0f bytes" % (n1, n2, marginal))
                if h1 is not None and h2 is not None:
                    hm = (h2 - h1) / (n2 - n1)
                    print("  of which contact history: %.0f bytes; the rest: %.0f bytes (target: <= 400 plus the "
                          "history)" % (hm, marginal - hm))

    print()
    print("Per CPU-second of the timed steps (robust to time-slicing on a loaded machine): LIGGGHTS from the "
          "deck's cpusec.sh lines, domel from /proc samples of its last timed_wall seconds; "
          "cpu/wall = share of a core the runs got")
    head = ["N", "domel median [min-max]", "LIGGGHTS median [min-max]", "ratio domel/LIGGGHTS", "cpu/wall"]
    lines = []
    for n in sizes:
        mine = [r for r in rows if r["N_requested"] == n and r.get("ok")]
        nact = next((r.get("N_actual") for r in mine if r.get("N_actual")), n)
        d = stats([r.get("particle_steps_per_cpu_s") for r in mine if r["code"] == "domel"])
        p = stats([r.get("particle_steps_per_cpu_s") for r in mine if r["code"] == "liggghts"])
        ratio = "%.2f" % (d[0] / p[0]) if d and p else "-"
        shares = [r["timed_cpu_s"] / r["timed_wall_s"] for r in mine
                  if r.get("timed_cpu_s") and r.get("timed_wall_s")]
        share = "%.2f-%.2f" % (min(shares), max(shares)) if shares else "-"
        lines.append([str(nact), fmt_rate(d), fmt_rate(p) if have_peer else "not run", ratio, share])
    print_md(head, lines)

    print()
    print("Sanity check (same physics?): mean particle-particle contacts per particle and translational KE at "
          "step %d (medians over runs), neighbour-list builds in %d steps (domel counts its initial build, " % (sum(steps()), sum(steps())) +
          "LIGGGHTS does not); a single jitter seed scatters by several %, see docs/benchmarks.md")
    head = ["N", "domel contacts/particle", "LIGGGHTS zmean", "difference", "KE domel/LIGGGHTS",
            "domel builds", "LIGGGHTS builds"]
    lines = []
    for n in sizes:
        mine = [r for r in rows if r["N_requested"] == n and r.get("ok")]
        nact = next((r.get("N_actual") for r in mine if r.get("N_actual")), n)
        zd = stats([r.get("mean_contacts_per_particle") for r in mine if r["code"] == "domel"])
        zp = stats([r.get("mean_contacts_per_particle") for r in mine if r["code"] == "liggghts"])
        bd = stats([r.get("neighbor_builds_total") for r in mine if r["code"] == "domel"])
        bp = stats([r.get("neighbor_builds_total") for r in mine if r["code"] == "liggghts"])
        kd = stats([r.get("ke_translational_final_J") for r in mine if r["code"] == "domel"])
        kp = stats([r.get("ke_translational_final_J") for r in mine if r["code"] == "liggghts"])
        diff = "%+.1f %%" % (100.0 * (zd[0] / zp[0] - 1.0)) if zd and zp and zp[0] else "-"
        kratio = "%.3f" % (kd[0] / kp[0]) if kd and kp and kp[0] else "-"
        lines.append([str(nact), "%.3f" % zd[0] if zd else "-", "%.3f" % zp[0] if zp else "-", diff, kratio,
                      "%g" % bd[0] if bd else "-", "%g" % bp[0] if bp else "-"])
    print_md(head, lines)


def print_md(head, lines):
    widths = [max(len(head[i]), *(len(l[i]) for l in lines)) if lines else len(head[i]) for i in range(len(head))]
    print("| " + " | ".join(h.ljust(w) for h, w in zip(head, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for l in lines:
        print("| " + " | ".join(c.ljust(w) for c, w in zip(l, widths)) + " |")


def fmt_csv(v):
    if isinstance(v, float):
        return "%.6g" % v
    return "" if v is None else v


def deck_title(deck, rolling):
    if deck == "bed":
        base = "Dense settled bed (bench/make_bed.py)"
        return base if rolling == "none" else base + " with rolling (LIGGGHTS %s vs domel %s)" % (
            make_s1.PEER_RF.get(rolling, rolling), make_s1.ROLLING[rolling]["model"])
    return "S1 settle" if rolling == "none" else "S2 settle+rolling (LIGGGHTS %s vs domel %s)" % (
        make_s1.PEER_RF.get(rolling, rolling), make_s1.ROLLING[rolling]["model"])


def report(csv_path):
    """Re-print the tables from a CSV written by an earlier run."""
    num = {"N_requested", "N_actual", "rep", "ok", "timed_steps", "neighbor_builds_total"}
    rows = []
    with open(csv_path, newline="") as f:
        for r in csv.DictReader(f):
            row = {}
            for k, v in r.items():
                if v == "" or k in ("timestamp", "code", "error", "log"):
                    row[k] = v if v != "" else None
                else:
                    try:
                        row[k] = int(v) if k in num else float(v)
                    except ValueError:
                        row[k] = v
            rows.append(row)
    sizes = []
    for r in rows:
        if r["N_requested"] not in sizes:
            sizes.append(r["N_requested"])
    print("Results from %s" % csv_path)
    base = os.path.basename(csv_path)
    DECK["name"] = "bed" if base.startswith("bed_") else "s1"
    deck = deck_title(DECK["name"], "none")
    for rf in make_s1.ROLLING:
        if base.startswith("s2_%s_" % rf) or base.startswith("bed_%s_" % rf):
            deck = deck_title(DECK["name"], rf)
    print_tables(rows, sizes, any(r["code"] == "liggghts" for r in rows), deck)
    return 0 if all(r.get("ok") for r in rows) else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description="S1 settle throughput: domel vs LIGGGHTS, interleaved.")
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 50000], help="requested N (default 10000 50000)")
    ap.add_argument("--with-200k", action="store_true", help="also run N = 200000 (~2.5 min per run per code)")
    ap.add_argument("--reps", type=int, default=3, help="runs per code and N (default 3)")
    ap.add_argument("--quick", action="store_true", help="smoke test: N = 10000, 1 rep")
    ap.add_argument("--no-peer", action="store_true", help="do not run LIGGGHTS")
    ap.add_argument("--domel", default=default_domel(),
                    help="domel binary (default build-bench/bin/domel, else build/bin/domel, else PATH)")
    ap.add_argument("--liggghts", default=shutil.which("liggghts"), help="LIGGGHTS binary (default: on PATH)")
    ap.add_argument("--peers", default=default_peers(), help="peers folder with liggghts/settle.in and cpusec.sh")
    ap.add_argument("--timeout", type=float, default=900, help="per-run timeout in s (default 900)")
    ap.add_argument("--results", default=os.path.join(HERE, "results"), help="CSV folder (default bench/results)")
    ap.add_argument("--rolling", choices=sorted(make_s1.ROLLING), default="none",
                    help="S1 (none, default) or S2: LIGGGHTS RF = cdt against domel dct (mu_r = 0.1), RF = epsd2 "
                         "against domel sd_critical_angle (theta_c = atan 0.1), or epsd2_plugin: RF = epsd2 against "
                         "the example plugin's epsd with the same model (Iwashita-Oda stiffness, no dashpot, "
                         "mu_r = 0.1), loaded by path")
    ap.add_argument("--epsd-library", help="with --rolling epsd2_plugin: the built libdomel_rolling_epsd.so (default: "
                                           "build examples/third_party_rolling against the --domel build tree's SDK)")
    ap.add_argument("--threads", type=int, nargs="+", default=[1],
                    help="domel thread counts to run (default 1; e.g. --threads 1 2); LIGGGHTS always runs serially")
    ap.add_argument("--ranks", type=int, default=1,
                    help="MPI ranks for both codes (default 1: one process each); with R > 1, domel also runs "
                         "as one process on R threads")
    ap.add_argument("--deck", choices=["s1", "bed"], default="s1",
                    help="s1: the peers' S1/S2 lattice column (default); bed: the dense settled bed of "
                         "bench/make_bed.py (both codes start from the same bed file; prepared once by domel, cached "
                         "in --bed-dir)")
    ap.add_argument("--bed-dir", default=os.path.join(HERE, "work"),
                    help="where make_bed.py keeps the prepared beds (default bench/work, git-ignored)")
    ap.add_argument("--report", metavar="CSV", help="only print the tables of an earlier run's CSV, run nothing")
    ap.add_argument("--workdir", help="where logs and domel outputs go (default: a fresh temp dir, kept)")
    args = ap.parse_args(argv)

    if args.report:
        return report(args.report)

    sizes = [10000] if args.quick else list(args.sizes)
    reps = 1 if args.quick else args.reps
    if args.with_200k and 200000 not in sizes:
        sizes.append(200000)
    if reps < 1 or any(n < 2 for n in sizes):
        ap.error("--reps must be >= 1 and every size >= 2")
    if args.domel:
        args.domel = os.path.abspath(args.domel) if os.sep in args.domel else args.domel
    if any(t < 1 for t in args.threads):
        ap.error("--threads expects counts >= 1")
    if args.ranks < 1 or (args.ranks > 1 and args.deck != "s1"):
        ap.error("--ranks expects a count >= 1, and runs the s1 deck only")
    RANKS["n"] = args.ranks
    if args.ranks > 1:
        args.threads = [1]
        env_ranks = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}
        os.environ.update(env_ranks)
    if not args.domel or not os.access(args.domel, os.X_OK):
        ap.error("no domel binary (build it: cmake -S . -B build-bench -G Ninja -DCMAKE_BUILD_TYPE=Release "
                 "-DDOMEL_BUILD_TESTS=OFF && cmake --build build-bench), or pass --domel")
    have_peer = not args.no_peer and bool(args.liggghts)
    if have_peer and not args.peers:
        print("warning: liggghts found but no peers folder with liggghts/settle.in; LIGGGHTS not run",
              file=sys.stderr)
        have_peer = False
    if not args.no_peer and not args.liggghts:
        print("note: liggghts is not on PATH; running domel only", file=sys.stderr)

    stamp = time.strftime("%Y%m%dT%H%M%S")
    workdir = os.path.abspath(args.workdir or tempfile.mkdtemp(prefix="domel_s1_%s_" % stamp))
    os.makedirs(workdir, exist_ok=True)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    deckdir = None
    if have_peer:
        # the deck calls `shell ../cpusec.sh`: copy liggghts/ and cpusec.sh keeping that layout (never write
        # into the shared peers folder)
        peer_copy = os.path.join(workdir, "peers")
        shutil.copytree(os.path.join(args.peers, "liggghts"), os.path.join(peer_copy, "liggghts"), dirs_exist_ok=True)
        shutil.copy2(os.path.join(args.peers, "cpusec.sh"), os.path.join(peer_copy, "cpusec.sh"))
        deckdir = os.path.join(peer_copy, "liggghts")
        shutil.copy2(os.path.join(HERE, "liggghts", "bed.in"), os.path.join(deckdir, "bed.in"))
    DECK["name"] = args.deck
    if args.deck == "bed":
        DECK["bed_dir"] = os.path.abspath(args.bed_dir)
        for n in sizes:  # untimed, before any timed run; cached between invocations
            _, facts = make_bed.prepare(n, DECK["bed_dir"], args.domel, threads=max(args.threads))
            print("bed N = %d: %.2f contacts per particle, solid fraction %.3f at the end of the preparation"
                  % (n, facts["contacts_per_particle_prep"], facts["solid_fraction_lower80"]))

    if args.rolling == "epsd2_plugin":
        if args.deck != "s1":
            ap.error("--rolling epsd2_plugin runs on the s1 deck only")
        lib = os.path.abspath(args.epsd_library) if args.epsd_library else build_epsd_example(args.domel, workdir)
        if not os.path.isfile(lib):
            ap.error("--epsd-library: no file %s" % lib)
        DECK["plugins"] = [lib]
        print("epsd example plugin: %s" % lib)

    info = machine_info()
    deck = deck_title(args.deck, args.rolling)
    print("%s benchmark %s on %s: %s cores, %s; load average %s" % (deck,
        stamp, info["host"], info["nproc"], info["cpu"], " ".join("%.2f" % x for x in os.getloadavg())))
    print("domel: %s" % args.domel)
    print("LIGGGHTS: %s" % (("%s, deck %s (copied to %s)" % (args.liggghts, os.path.join(args.peers, "liggghts"),
                                                                 deckdir)) if have_peer else "not run"))
    print("sizes %s, %d rep(s), logs in %s" % (" ".join(map(str, sizes)), reps, workdir))
    if args.ranks > 1:
        print("both codes on %d MPI ranks (code domel, liggghts); domel_%dt: domel as one process on %d threads"
              % (args.ranks, args.ranks, args.ranks))
    print()

    os.makedirs(args.results, exist_ok=True)
    if args.deck == "bed":
        csv_name = ("bed_%s.csv" % stamp) if args.rolling == "none" else ("bed_%s_%s.csv" % (args.rolling, stamp))
    else:
        csv_name = ("s1_%s.csv" % stamp) if args.rolling == "none" else ("s2_%s_%s.csv" % (args.rolling, stamp))
    csv_path = os.path.join(args.results, csv_name)
    rows = []
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        w.writeheader()
        for n in sizes:
            for rep in range(1, reps + 1):
                jobs = [("domel", lambda t=t: run_domel(args.domel, n, rep, workdir, args.timeout, env, t,
                                                        args.rolling, args.ranks))
                        for t in args.threads]
                if args.ranks > 1:  # one process on as many threads, for the ranks-against-threads table
                    jobs.append(("domel", lambda: run_domel(args.domel, n, rep, workdir, args.timeout, env,
                                                            args.ranks, args.rolling, 1)))
                if have_peer:
                    jobs.append(("liggghts", lambda: run_liggghts(args.liggghts, deckdir, n, rep, workdir,
                                                                  args.timeout, env, args.rolling)))
                for _, job in jobs:
                    row = job()
                    row["timestamp"] = time.strftime("%Y-%m-%dT%H:%M:%S")
                    rows.append(row)
                    w.writerow({k: fmt_csv(row.get(k)) for k in CSV_FIELDS})
                    f.flush()
                    if row.get("ok"):
                        extra = ""
                        if row.get("timed_cpu_s"):
                            extra = ", cpu %.2f s -> %.4g per cpu-s" % (row["timed_cpu_s"],
                                                                        row["particle_steps_per_cpu_s"])
                        print("%-8s N=%-6s rep %d: %.4g particle-steps/s (timed %.2f s%s; process %.1f s wall, "
                              "%.1f s cpu; contacts/particle %s; load %.2f -> %.2f)" % (
                                  row["code"], row["N_actual"], rep, row["particle_steps_per_s"],
                                  row["timed_wall_s"], extra, row["process_wall_s"], row["process_cpu_s"],
                                  ("%.3f" % row["mean_contacts_per_particle"])
                                  if row.get("mean_contacts_per_particle") is not None else "-",
                                  row["load1_start"], row["load1_end"]), flush=True)
                    else:
                        print("%-8s N=%-6s rep %d: FAILED: %s" % (row["code"], n, rep, row.get("error")),
                              flush=True)

    print_tables(rows, sizes, have_peer, deck)
    print()
    print("CSV: %s" % csv_path)
    failed = [r for r in rows if not r.get("ok")]
    if failed:
        print("%d run(s) failed" % len(failed), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
