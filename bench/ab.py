#!/usr/bin/env python3
"""A/B speed gate: two domel binaries (old and new) on the benchmark decks, alternating run by run.

What is measured (see docs/benchmarks.md, "A/B gate between two builds"):
  The decks of bench/run_s1.py, generated and run by its own functions (no LIGGGHTS):
    s1      S1 settle: the peers' lattice column compacting under gravity (bench/make_s1.py, rolling none),
            2000 untimed + 2000 timed steps;
    s2_dct  S2: S1 with domel's dct rolling resistance (mu_r = 0.1; run_s1.py --rolling cdt);
    s2_sd   S2: S1 with domel's sd_critical_angle rolling (theta_c = atan 0.1; run_s1.py --rolling epsd2);
    bed     the dense settled bed (bench/make_bed.py; prepared once by the OLD binary, cached in --bed-dir and
            then run by both from the same file), 500 untimed + 2000 timed steps.
  Each run is `domel run SCENARIO --quiet --time-after <untimed> --threads T` with OMP_NUM_THREADS=1, exactly as
  run_s1.py runs it; the number is summary.json "timed_window" particle-steps per wall-clock second of the timed
  steps. For every case x N x threads the runs alternate old, new, old, new, ... (--reps of each), so that slow
  drifts of the machine's load hit both binaries alike. Each binary loads the plugins of its own build tree
  (<binary>/../../plugins, i.e. build/plugins next to build/bin); DOMEL_PLUGIN_PATH is removed from the runs'
  environment so that neither picks up the other's (or a third) plugin folder; `domel plugins --json` is asked
  at the start and the plugin libraries each binary loads are printed.

  Recorded per run (CSV bench/results/ab_<timestamp>.csv): case, N requested/actual, threads, binary (old/new),
  rep, particle-steps/s, timed wall, particle-steps per CPU-second of the timed steps (as run_s1.py samples it),
  process wall/CPU, load average, and as a same-physics check the final mean contacts per particle, translational
  kinetic energy and neighbour-list builds from summary.json (full precision, so identical results compare equal).

  Printed: per case x N x threads the median [min-max] of old and of new, new/old of the medians (and of the
  per-CPU-second medians), flagged `SLOWER>3%` where new/old < 0.97; then whether the final states agree.

  --callgrind: for each case at N = --callgrind-size (10000) on one thread, each binary runs once under
  `valgrind --tool=callgrind` for --callgrind-steps (300) steps (`--max-steps`); the total instructions (Ir, the
  `totals:`/`summary:` line of the callgrind output file) of old and new are printed with new/old, flagged
  `HIGHER>2%` above 1.02. The count is deterministic to far below 1 %, so it resolves what a 3 % wall-clock gate
  cannot on a noisy machine. It includes setup (scenario load, plugins, insertion, the first neighbour build) and,
  on S1/S2, only the start of the fall from the lattice (few contacts); the bed is contact-heavy from step 1.
  --callgrind-from K: instead, the steps K+1 .. K+S alone (S = --callgrind-steps), as the difference of a run of
  K + S steps and one of K steps: no setup (scenario load, plugin loading and relocation, the initial overlap
  check), which a binary with more plugin libraries pays once per run; K = 2000 counts the benchmarks' timed window.

Usage:
    python3 bench/ab.py --old OLD/build/bin/domel --new NEW/build/bin/domel            # the full gate's timing
    python3 bench/ab.py --old A --new B --cases s1 s2_dct s2_sd bed --sizes 10000 50000 --threads 1 2 --reps 5
    python3 bench/ab.py --old A --new B --reps 0 --callgrind                         # instruction counts only
    python3 bench/ab.py --old A --new B --sizes 2000 --reps 1 --threads 1 --cases s1 # smoke test
Exit status: 0 when every run succeeded (whatever the speed), 1 when any failed (the others still run),
2 on bad usage. Only the Python standard library is used.
"""

import argparse
import csv
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_bed  # noqa: E402  (same folder)
import run_s1  # noqa: E402

# case -> (run_s1 deck, run_s1 --rolling value)
CASES = {
    "s1": ("s1", "none"),
    "s2_dct": ("s1", "cdt"),
    "s2_sd": ("s1", "epsd2"),
    "bed": ("bed", "none"),
}
BINARIES = ("old", "new")
SLOWER = 0.97          # flag new/old throughput below this
HIGHER_IR = 1.02       # flag new/old instructions above this

CSV_FIELDS = [
    "timestamp", "mode", "case", "N_requested", "N_actual", "threads", "binary", "rep", "ok", "steps", "first_step",
    "timed_steps", "timed_wall_s", "particle_steps_per_s", "timed_cpu_s", "particle_steps_per_cpu_s",
    "process_wall_s", "process_cpu_s", "load1_start", "load1_end", "instructions_Ir",
    "mean_contacts_per_particle", "ke_translational_final_J", "neighbor_builds_total", "peak_rss_bytes",
    "error", "log",
]


def set_deck(case, bed_dir):
    """Point run_s1's deck machinery at a case; return its rolling value."""
    deck, rolling = CASES[case]
    run_s1.DECK["name"] = deck
    run_s1.DECK["bed_dir"] = bed_dir
    return rolling


def plugin_dirs(binary):
    """The folders domel's default_plugin_directories() derives from the binary's real location."""
    tree = os.path.dirname(os.path.dirname(os.path.realpath(binary)))
    return [os.path.join(tree, "plugins"), os.path.join(tree, "lib", "domel", "plugins")]


def loaded_plugins(binary, env):
    """Plugin library paths a binary loads (`domel plugins --json`), or an error string."""
    try:
        out = subprocess.run([binary, "plugins", "--json"], env=env, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return "could not run: %s" % exc
    if out.returncode != 0:
        return "exit %d: %s" % (out.returncode, out.stderr.strip()[-300:])
    try:
        models = json.loads(out.stdout)
    except ValueError:
        return "unreadable output"
    return sorted({m.get("path", "?") for m in models})


def version(binary, env):
    try:
        out = subprocess.run([binary, "version"], env=env, capture_output=True, text=True, timeout=60)
        return " ".join(out.stdout.split())[:200] or "?"
    except (OSError, subprocess.TimeoutExpired):
        return "?"


def parse_callgrind(path):
    """Total Ir from a callgrind output file ('events:' names the columns; 'totals:' else 'summary:')."""
    events, totals, summary = None, None, None
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("events:"):
                events = line.split(":", 1)[1].split()
            elif line.startswith("totals:"):
                totals = line.split(":", 1)[1].split()
            elif line.startswith("summary:"):
                summary = line.split(":", 1)[1].split()
    vals = totals or summary
    if not vals:
        return None
    k = events.index("Ir") if events and "Ir" in events else 0
    return int(vals[k]) if k < len(vals) else None


def run_timed_case(binary, which, case, n, threads, rep, workdir, timeout, env):
    rolling = CASES[case][1]
    wd = os.path.join(workdir, "%s_%s" % (case, which))
    os.makedirs(wd, exist_ok=True)
    row = run_s1.run_domel(binary, n, rep, wd, timeout, env, threads, rolling)
    row.update(mode="timed", case=case, threads=threads, binary=which, steps=sum(run_s1.steps()))
    return row


def run_callgrind_case(binary, which, case, n, nsteps, workdir, timeout, env, valgrind, first=0):
    """Ir of one binary on one case: the whole process of nsteps steps (first = 0), or the steps first+1 ..
    first+nsteps alone (the difference of a run of first + nsteps steps and one of first steps)."""
    if first > 0:
        rows = [run_callgrind_case(binary, which, case, n, k, workdir, timeout, env, valgrind)
                for k in (first, first + nsteps)]
        row = dict(rows[1])
        row.update(steps=nsteps, first_step=first + 1, process_wall_s=rows[0]["process_wall_s"] + rows[1]["process_wall_s"])
        if not (rows[0].get("ok") and rows[1].get("ok")):
            row.update(ok=0, error=rows[0].get("error") or rows[1].get("error"))
        else:
            row["instructions_Ir"] = rows[1]["instructions_Ir"] - rows[0]["instructions_Ir"]
        return row
    rolling = CASES[case][1]
    wd = os.path.join(workdir, "%s_%s" % (case, which))
    os.makedirs(wd, exist_ok=True)
    scen = run_s1.deck_scenario(n, wd, rolling)
    outdir = os.path.join(wd, "callgrind_N%d_%d" % (n, nsteps))
    log = outdir + ".screen"
    cg_out = outdir + ".callgrind.out"
    row = {"mode": "callgrind", "case": case, "N_requested": n, "threads": 1, "binary": which, "rep": 1,
           "steps": nsteps, "log": log, "load1_start": run_s1.load1()}
    shutil.rmtree(outdir, ignore_errors=True)  # a fresh folder (domel refuses one with an earlier run's output)
    cmd = [valgrind, "--tool=callgrind", "--callgrind-out-file=" + cg_out, binary, "run", scen, "--out", outdir,
           "--quiet", "--threads", "1", "--max-steps", str(nsteps)]
    rc, wall, cpu, _ = run_s1.run_timed(cmd, wd, log, timeout, env, sample_s=0.2)
    row.update(load1_end=run_s1.load1(), process_wall_s=wall, process_cpu_s=cpu)
    summary_path = os.path.join(outdir, "summary.json")
    if rc != 0 or not os.path.isfile(summary_path) or not os.path.isfile(cg_out):
        row.update(ok=0, error="valgrind/domel exit %d (see %s)" % (rc, log))
        return row
    with open(summary_path) as f:
        s = json.load(f)
    row.update(run_s1.summary_final(s), N_actual=s.get("particles"), peak_rss_bytes=s.get("peak_rss_bytes"))
    row["instructions_Ir"] = parse_callgrind(cg_out)
    if row["instructions_Ir"] is None:
        row.update(ok=0, error="no totals/summary line in %s" % cg_out)
    elif row["N_actual"] != run_s1.expected_particles(n):
        row.update(ok=0, error="N_actual %s != %d" % (row["N_actual"], run_s1.expected_particles(n)))
    else:
        row["ok"] = 1
    return row


def fmt_csv(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else v


def med(values):
    v = [x for x in values if isinstance(x, (int, float))]
    return (statistics.median(v), min(v), max(v), len(v)) if v else None


def fmt_stat(st):
    return "%.4g [%.4g-%.4g] (%d)" % st if st else "-"


def groups(rows, mode):
    keys = []
    for r in rows:
        if r.get("mode") == mode:
            k = (r["case"], r["N_requested"], r["threads"])
            if k not in keys:
                keys.append(k)
    return keys


def pick(rows, mode, key, which, field):
    return [r.get(field) for r in rows if r.get("mode") == mode and r.get("ok") and r["binary"] == which
            and (r["case"], r["N_requested"], r["threads"]) == key]


def nact(rows, key):
    return next((r.get("N_actual") for r in rows if (r["case"], r["N_requested"], r["threads"]) == key
                 and r.get("N_actual")), key[1])


def same_state(rows, mode, key):
    """(text for contacts, text for KE, verdict) comparing the final states of old and new runs."""
    out = []
    verdict = []
    for field, fmt in (("mean_contacts_per_particle", "%.4f"), ("ke_translational_final_J", "%.5g")):
        o = [v for v in pick(rows, mode, key, "old", field) if v is not None]
        n = [v for v in pick(rows, mode, key, "new", field) if v is not None]
        if not o or not n:
            out.append("-")
            verdict.append("no data")
            continue
        mo, mn = statistics.median(o), statistics.median(n)
        d = (mn / mo - 1.0) * 100.0 if mo else float("nan")
        out.append((fmt + " / " + fmt + " (%+.2f %%)") % (mo, mn, d))
        if len(set(o)) == 1 and set(o) == set(n):
            verdict.append("identical")
        elif len(set(o)) > 1 or len(set(n)) > 1:
            verdict.append("runs of one binary differ; compare medians")
        else:
            verdict.append("DIFFERENT")
    v = verdict[0] if verdict[0] == verdict[1] else "; ".join("%s: %s" % (f, x) for f, x in
                                                            zip(("contacts", "KE"), verdict))
    return out[0], out[1], v


def print_tables(rows):
    slow, diff = [], []
    keys = groups(rows, "timed")
    if keys:
        print()
        print("Timed particle-steps/s (timed window of summary.json; medians [min-max] (runs); new/old of the "
              "medians; per CPU-s = per CPU-second of the timed steps, the cross-check on a loaded machine)")
        lines = []
        for key in keys:
            o = med(pick(rows, "timed", key, "old", "particle_steps_per_s"))
            n = med(pick(rows, "timed", key, "new", "particle_steps_per_s"))
            oc = med(pick(rows, "timed", key, "old", "particle_steps_per_cpu_s"))
            nc = med(pick(rows, "timed", key, "new", "particle_steps_per_cpu_s"))
            ratio = n[0] / o[0] if o and n else None
            cratio = nc[0] / oc[0] if oc and nc else None
            flag = ""
            if ratio is not None and ratio < SLOWER:
                flag = "SLOWER>3%"
                slow.append(key)
            elif ratio is None:
                flag = "no result"
            lines.append([key[0], str(nact(rows, key)), str(key[2]), fmt_stat(o), fmt_stat(n),
                          "%.3f" % ratio if ratio else "-", "%.3f" % cratio if cratio else "-", flag])
        run_s1.print_md(["case", "N", "threads", "old median [min-max]", "new median [min-max]", "new/old",
                         "new/old per CPU-s", "flag"], lines)
        print()
        print("Same physics? Final mean contacts per particle and translational KE (median old / median new, new "
              "against old); identical = every run of both binaries gave the same doubles. A change of the "
              "floating-point summation order legitimately moves the chaotic S1/S2 column by a few %; the bed, "
              "starting at rest, should stay close")
        lines = []
        for key in keys:
            c, k, v = same_state(rows, "timed", key)
            if v not in ("identical", "no data"):
                diff.append(key)
            lines.append([key[0], str(nact(rows, key)), str(key[2]), c, k, v])
        run_s1.print_md(["case", "N", "threads", "contacts/particle old / new", "KE [J] old / new", "verdict"], lines)

    keys = groups(rows, "callgrind")
    high = []
    if keys:
        print()
        firsts = sorted({r.get("first_step", 1) for r in rows if r.get("mode") == "callgrind"})
        steps = "/".join(sorted({str(r["steps"]) for r in rows if r.get("mode") == "callgrind"}))
        if firsts == [1]:
            print("Instructions (callgrind Ir, one thread, whole process: setup + the first %s steps)" % steps)
        else:
            print("Instructions (callgrind Ir, one thread, of the %s steps from step %s on alone: the difference "
                  "of two runs, so setup is not in it)" % (steps, "/".join(str(f) for f in firsts)))
        lines = []
        for key in keys:
            o = pick(rows, "callgrind", key, "old", "instructions_Ir")
            n = pick(rows, "callgrind", key, "new", "instructions_Ir")
            ratio = n[0] / o[0] if o and n and o[0] else None
            flag = ""
            if ratio is not None and ratio > HIGHER_IR:
                flag = "HIGHER>2%"
                high.append(key)
            elif ratio is None:
                flag = "no result"
            _, _, v = same_state(rows, "callgrind", key)
            lines.append([key[0], str(nact(rows, key)), "{:,}".format(o[0]) if o else "-",
                          "{:,}".format(n[0]) if n else "-", "%.4f" % ratio if ratio else "-", flag, v])
        run_s1.print_md(["case", "N", "Ir old", "Ir new", "new/old", "flag", "final state"], lines)
    return slow, diff, high


def main(argv=None):
    ap = argparse.ArgumentParser(description="A/B speed gate: old vs new domel binary, alternating run by run.")
    ap.add_argument("--old", required=True, help="the reference domel binary (e.g. main's build/bin/domel)")
    ap.add_argument("--new", required=True, help="the candidate domel binary")
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES),
                    help="decks (default all: s1 s2_dct s2_sd bed)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 50000], help="requested N (default 10000 50000)")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2], help="thread counts (default 1 2)")
    ap.add_argument("--reps", type=int, default=5,
                    help="timed runs per binary and case x N x threads (default 5; 0 = only --callgrind)")
    ap.add_argument("--callgrind", action="store_true",
                    help="also count instructions: each case once per binary under valgrind's callgrind")
    ap.add_argument("--callgrind-steps", type=int, default=300, help="steps of a callgrind run (default 300)")
    ap.add_argument("--callgrind-size", type=int, default=10000, help="N of the callgrind runs (default 10000)")
    ap.add_argument("--callgrind-from", type=int, default=0,
                    help="count only the steps after this many: each binary runs --callgrind-from and "
                         "--callgrind-from + --callgrind-steps steps, and the difference is compared (setup, "
                         "plugin loading and the first steps left out; default 0: the whole process)")
    ap.add_argument("--timeout", type=float, default=900, help="per timed run, s (default 900)")
    ap.add_argument("--callgrind-timeout", type=float, default=3600, help="per callgrind run, s (default 3600)")
    ap.add_argument("--results", default=os.path.join(HERE, "results"), help="CSV folder (default bench/results)")
    ap.add_argument("--bed-dir", default=os.path.join(HERE, "work"),
                    help="prepared beds (default bench/work, git-ignored; shared with run_s1.py --deck bed)")
    ap.add_argument("--workdir", help="logs and domel outputs (default: a fresh temp dir, kept)")
    args = ap.parse_args(argv)

    for name in ("old", "new"):
        p = getattr(args, name)
        p = os.path.abspath(p) if os.sep in p else (shutil.which(p) or p)
        if not os.path.isfile(p) or not os.access(p, os.X_OK):
            ap.error("--%s: %s is not an executable file" % (name, p))
        setattr(args, name, p)
    if args.reps < 0 or args.callgrind_steps < 1 or args.callgrind_from < 0 or \
            any(n < 2 for n in args.sizes + [args.callgrind_size]):
        ap.error("--reps must be >= 0, --callgrind-steps >= 1, --callgrind-from >= 0 and every size >= 2")
    if any(t < 1 for t in args.threads):
        ap.error("--threads expects counts >= 1")
    if args.reps == 0 and not args.callgrind:
        ap.error("--reps 0 runs nothing without --callgrind")
    valgrind = shutil.which("valgrind")
    if args.callgrind and not valgrind:
        ap.error("--callgrind needs valgrind on PATH (apt-get install valgrind)")

    stamp = time.strftime("%Y%m%dT%H%M%S")
    workdir = os.path.abspath(args.workdir or tempfile.mkdtemp(prefix="domel_ab_%s_" % stamp))
    os.makedirs(workdir, exist_ok=True)
    bed_dir = os.path.abspath(args.bed_dir)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if env.pop("DOMEL_PLUGIN_PATH", None) is not None:
        print("note: DOMEL_PLUGIN_PATH is removed for these runs: each binary loads its own tree's plugins")
    env.pop("DOMEL_THREADS", None)  # --threads is always passed; keep the environment out of it

    info = run_s1.machine_info()
    print("domel A/B %s on %s: %s cores, %s; load average %s" % (
        stamp, info["host"], info["nproc"], info["cpu"], " ".join("%.2f" % x for x in os.getloadavg())))
    bad_plugins = False
    for name in BINARIES:
        b = getattr(args, name)
        print("%s: %s (%s)" % (name, b, version(b, env)))
        libs = loaded_plugins(b, env)
        if isinstance(libs, str):
            print("  plugins: %s" % libs)
            bad_plugins = True
            continue
        dirs = [os.path.realpath(d) for d in plugin_dirs(b)]
        foreign = [l for l in libs if not any(os.path.realpath(l).startswith(d + os.sep) for d in dirs)]
        print("  plugins: %d librar%s from %s" % (len(libs), "y" if len(libs) == 1 else "ies",
                                                 ", ".join(sorted({os.path.dirname(l) for l in libs})) or "-"))
        if not libs:
            print("  WARNING: no plugin libraries (expected in %s)" % " or ".join(plugin_dirs(b)))
            bad_plugins = True
        if foreign:
            print("  WARNING: libraries outside the binary's own tree: %s" % ", ".join(foreign))
    if os.path.realpath(args.old) == os.path.realpath(args.new):
        print("note: old and new are the same file (a smoke test or a noise measurement)")
    print("cases %s; %s; %s; logs in %s" % (
        " ".join(args.cases),
        ("timed: sizes %s, threads %s, %d rep(s) per binary" % (" ".join(map(str, args.sizes)),
                                                              " ".join(map(str, args.threads)), args.reps))
        if args.reps else "no timed runs",
        ("callgrind: N = %d, %d steps%s, 1 thread" % (args.callgrind_size, args.callgrind_steps,
                                                       " after %d" % args.callgrind_from if args.callgrind_from else ""))
        if args.callgrind else "no callgrind", workdir))
    if bad_plugins:
        print("a binary could not list its plugins; the runs may fail", file=sys.stderr)

    if "bed" in args.cases:
        sizes = sorted(set((args.sizes if args.reps else []) + ([args.callgrind_size] if args.callgrind else [])))
        for n in sizes:  # untimed, before any timed run; cached between invocations; the same file for both
            try:
                _, facts = make_bed.prepare(n, bed_dir, args.old, threads=max(args.threads))
            except (OSError, subprocess.CalledProcessError, RuntimeError, KeyError, ValueError) as exc:
                print("bed preparation for N = %d failed: %s" % (n, exc), file=sys.stderr)
                return 1
            print("bed N = %d: %.2f contacts per particle, solid fraction %.3f (prepared by the old binary, "
                  "cached in %s)" % (n, facts["contacts_per_particle_prep"], facts["solid_fraction_lower80"], bed_dir))
    print()

    os.makedirs(args.results, exist_ok=True)
    csv_path = os.path.join(args.results, "ab_%s.csv" % stamp)
    rows = []
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        w.writeheader()

        def record(row):
            row["timestamp"] = time.strftime("%Y-%m-%dT%H:%M:%S")
            rows.append(row)
            w.writerow({k: fmt_csv(row.get(k)) for k in CSV_FIELDS})
            f.flush()
            tag = "%-6s %-3s N=%-6s %dt rep %d" % (row["case"], row["binary"], row.get("N_actual") or
                                                  row["N_requested"], row["threads"], row["rep"])
            if not row.get("ok"):
                print("%s: FAILED: %s" % (tag, row.get("error")), flush=True)
            elif row["mode"] == "timed":
                print("%s: %.4g particle-steps/s (timed %.2f s, process %.1f s; contacts/particle %s; load %.2f)" % (
                    tag, row["particle_steps_per_s"], row["timed_wall_s"], row["process_wall_s"],
                    "%.4f" % row["mean_contacts_per_particle"] if row.get("mean_contacts_per_particle") is not None
                    else "-", row["load1_start"]), flush=True)
            else:
                print("%s: callgrind %d steps: Ir %s (%.0f s under valgrind)" % (
                    tag, row["steps"], "{:,}".format(row["instructions_Ir"]), row["process_wall_s"]), flush=True)

        for case in args.cases:
            set_deck(case, bed_dir)
            for n in args.sizes:
                for t in args.threads:
                    for rep in range(1, args.reps + 1):
                        for which in BINARIES:
                            record(run_timed_case(getattr(args, which), which, case, n, t, rep, workdir,
                                                  args.timeout, env))
        if args.callgrind:
            for case in args.cases:
                set_deck(case, bed_dir)
                for which in BINARIES:
                    record(run_callgrind_case(getattr(args, which), which, case, args.callgrind_size,
                                              args.callgrind_steps, workdir, args.callgrind_timeout, env, valgrind,
                                              args.callgrind_from))

    slow, diff, high = print_tables(rows)
    print()
    failed = [r for r in rows if not r.get("ok")]
    print("Summary: %d run(s), %d failed; %d case(s) SLOWER>3%%, %d with more than 2 %% more instructions, "
          "%d with a final state that is not identical" % (len(rows), len(failed), len(slow), len(high), len(diff)))
    print("CSV: %s" % csv_path)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
