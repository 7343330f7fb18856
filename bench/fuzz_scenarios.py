#!/usr/bin/env python3
"""Fuzz the scenario reader and validator, or runs (docs/reliability.md).

Builds tests/fuzz/scenario_fuzz.cpp with clang, libFuzzer, AddressSanitizer
and UndefinedBehaviorSanitizer in build-fuzz/ (the platform and the built-in
plugins instrumented too), seeds a corpus with every scenario of the config
corpus (tests/config/cases) and every shipped scenario (scenarios/), copies
the STL meshes and state files they name into the fuzzer's working folder
(so relative paths resolve), then runs libFuzzer until --runs executions
(default 10^6) or --max-time seconds, and prints the executions done, the
corpus size and every crash, hang or sanitizer report found (files
crash-*, timeout-*, oom-* in the artefact folder). Each finding belongs in
tests/config/cases as a corpus case once fixed.

With --harness run it builds tests/fuzz/run_fuzz.cpp instead, which also
runs every accepted scenario of few particles for up to 200 macro steps and
checks the state after (finite, exact mass books, no particle past a wall's
surface without the wall's contact; docs/reliability.md, "Run-time
fuzzing"). Its corpus is seeded with the small runnable scenarios of
tests/fuzz/seeds first, then the same files as the validator's, in its own
folder (default build-fuzz/run-time), and it also prints how many inputs
were refused, how many ran steps, how many runs stopped with the platform's
own error, and the kinds of those errors.

Usage: bench/fuzz_scenarios.py [--harness validate|run] [--runs N] [--max-time S] [--jobs J] [--work DIR]
                               [--build-jobs N]
Needs clang (Debian's clang package has libFuzzer).
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


HARNESSES = {"validate": "domel_scenario_fuzz", "run": "domel_run_fuzz"}


def build(build_dir, target, jobs):
    env = dict(os.environ, CC="clang", CXX="clang++")
    subprocess.run(["cmake", "-S", ROOT, "-B", build_dir, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                    "-DDOMEL_FUZZ=ON", "-DDOMEL_SANITIZE=address,undefined", "-DDOMEL_BUILD_TESTS=OFF"],
                   check=True, env=env, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", build_dir] + (["-j%d" % jobs] if jobs else []) +
                   ["--target", target, "domel_contact_std", "domel_controller_std", "domel_fluid_std",
                    "domel_insertion_std", "domel_rolling_std"],
                   check=True, env=env)
    return os.path.join(build_dir, "tests", "fuzz", target)


def seed_corpus(corpus, workdir, harness):
    os.makedirs(corpus, exist_ok=True)
    os.makedirs(workdir, exist_ok=True)
    seeds = sorted(glob.glob(os.path.join(ROOT, "tests", "config", "cases", "*.json")) +
                   glob.glob(os.path.join(ROOT, "scenarios", "**", "*.json"), recursive=True))
    if harness == "run":  # the small runnable scenarios first
        seeds = sorted(glob.glob(os.path.join(ROOT, "tests", "fuzz", "seeds", "*.json"))) + seeds
    for k, f in enumerate(seeds):
        shutil.copy(f, os.path.join(corpus, "seed_%03d_%s" % (k, os.path.basename(f))))
    # files the scenarios name by relative path: meshes and state files
    for f in (glob.glob(os.path.join(ROOT, "scenarios", "**", "*.stl"), recursive=True) +
              glob.glob(os.path.join(ROOT, "tests", "config", "cases", "*.stl")) +
              glob.glob(os.path.join(ROOT, "tests", "config", "cases", "*.csv")) +
              glob.glob(os.path.join(ROOT, "tests", "fuzz", "seeds", "*.csv"))):
        shutil.copy(f, os.path.join(workdir, os.path.basename(f)))
    return len(seeds)


def run_report(workdir):
    """The run harness's counts (run_stats_<pid>.txt, one per fuzzer process),
    summed, and the kinds of run errors (run_errors_<pid>.txt)."""
    total = {}
    for f in glob.glob(os.path.join(workdir, "run_stats_*.txt")):
        words = open(f).read().split()
        for key, value in zip(words[1::2], words[2::2]):
            total[key] = total.get(key, 0) + int(value)
    kinds = set()
    for f in glob.glob(os.path.join(workdir, "run_errors_*.txt")):
        kinds.update(line.rstrip("\n") for line in open(f, errors="replace") if line.strip())
    return total, sorted(kinds)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--harness", choices=sorted(HARNESSES), default="validate",
                    help="validate: read, validate and build each input; run: also run the accepted ones")
    ap.add_argument("--runs", type=int, default=1000000)
    ap.add_argument("--max-time", type=int, default=0, help="seconds (0: until --runs)")
    ap.add_argument("--jobs", type=int, default=1, help="parallel fuzzer processes (libFuzzer -workers)")
    ap.add_argument("--work", default=None, help="working folder (default build-fuzz/run, with --harness run "
                    "build-fuzz/run-time)")
    ap.add_argument("--timeout", type=int, default=None,
                    help="seconds one input may take before it counts as a hang (default 20; 60 with --harness run, "
                         "whose time-step estimate of a contact far too soft for its impact velocity takes 20-30 s "
                         "under the sanitizers)")
    ap.add_argument("--max-len", type=int, default=16384, help="largest input the fuzzer makes, bytes")
    ap.add_argument("--build-jobs", type=int, default=0, help="parallel compile jobs (0: ninja's default)")
    args = ap.parse_args()
    if args.timeout is None:
        args.timeout = 60 if args.harness == "run" else 20
    if args.work is None:
        args.work = os.path.join(ROOT, "build-fuzz", "run-time" if args.harness == "run" else "run")
    if not shutil.which("clang++"):
        sys.exit("clang++ is needed (apt-get install clang)")
    fuzzer = build(os.path.join(ROOT, "build-fuzz"), HARNESSES[args.harness], args.build_jobs)
    corpus = os.path.join(args.work, "corpus")
    artefacts = os.path.join(args.work, "artefacts") + os.sep
    workdir = os.path.join(args.work, "files")
    os.makedirs(artefacts, exist_ok=True)
    seeds = seed_corpus(corpus, workdir, args.harness)
    for old in glob.glob(os.path.join(workdir, "run_stats_*.txt")) + glob.glob(os.path.join(workdir, "run_errors_*.txt")):
        os.remove(old)
    # Leaks are checked after every input that allocated more than it freed
    # (libFuzzer's -detect_leaks), which is where a leak in domel's reader or
    # validator shows. The check when the process ends is off: it reports the
    # one-time allocations of OpenMPI (initialised by hypre for fluid
    # scenarios), which scripts/sanitize suppresses by library name; that
    # needs the slow unwinder (fast_unwind_on_malloc=0), which makes every
    # allocation some 60 times slower and the fuzzer useless.
    env = dict(os.environ, DOMEL_FUZZ_WORKDIR=workdir,
               ASAN_OPTIONS="detect_leaks=1:leak_check_at_exit=0:abort_on_error=1",
               LSAN_OPTIONS="suppressions=%s" % os.path.join(ROOT, "tests", "sanitize", "lsan.supp"),
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    cmd = [fuzzer, corpus, "-artifact_prefix=" + artefacts, "-timeout=%d" % args.timeout,
           "-max_len=%d" % args.max_len, "-rss_limit_mb=4096", "-print_final_stats=1",
           "-dict=" + os.path.join(ROOT, "tests", "fuzz", "scenario.dict")]
    if args.max_time:
        cmd.append("-max_total_time=%d" % args.max_time)
    if args.jobs > 1:
        per = args.runs // args.jobs
        cmd += ["-jobs=%d" % args.jobs, "-workers=%d" % args.jobs, "-runs=%d" % per]
    else:
        cmd.append("-runs=%d" % args.runs)
    log = os.path.join(args.work, "fuzz.log")
    for old in glob.glob(os.path.join(args.work, "fuzz-*.log")):
        os.remove(old)
    print("fuzzing: %s (log %s)" % (" ".join(cmd), log), flush=True)
    start = time.time()
    with open(log, "w") as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT, env=env, cwd=args.work)
    wall = time.time() - start
    # with --jobs, each job writes its own fuzz-<n>.log in the working folder
    # each log prints its final stats more than once: count the largest per log
    execs, corp = [], []
    # (the main log repeats the jobs' logs when there are jobs: read it only without)
    for f in sorted(glob.glob(os.path.join(args.work, "fuzz-*.log"))) or [log]:
        text = open(f, errors="replace").read()
        n = [int(x) for x in re.findall(r"stat::number_of_executed_units:\s+(\d+)", text)]
        execs.append(max(n) if n else 0)
        c = re.findall(r"cov: (\d+) ft: \d+ corp: (\d+)/", text)
        if c:
            corp.append("cov %s, corpus %s" % c[-1])
    found = sorted(os.listdir(artefacts))
    print("exit code %d; executions %d; seeds %d; corpus folder now %d files; last status per job: %s; findings: %s" %
          (rc, sum(execs), seeds, len(os.listdir(corpus)), "; ".join(corp) or "none",
           ", ".join(found) if found else "none"))
    print("wall time %.0f s; %.1f executions per second over all jobs" % (wall, sum(execs) / wall if wall > 0 else 0))
    if args.harness == "run":
        total, kinds = run_report(workdir)
        inputs = total.get("inputs", 0)
        share = lambda k: "%d (%.1f %%)" % (total.get(k, 0), 100.0 * total.get(k, 0) / inputs if inputs else 0)
        print("run harness: inputs %d; refused %s; not run (a cost knob, particles, sub-steps or fluid cells above the harness's ceilings) %s; ran steps %s; run returned and "
              "checked %s; stopped by a refusal from run() %s, by a RuntimeError or PluginError %s, by the harness "
              "(particles or wall time) %s; runs that ended with a particle past a wall's surface, its contact acting, %s; "
              "%d macro steps, %d particle-macro-steps" %
              (inputs, share("refused"), share("too_large"), share("stepped"), share("completed"),
               share("run_refused"), share("run_failed"), share("cut"), share("past_wall"),
               total.get("macro_steps", 0), total.get("particle_steps", 0)))
        print("kinds of run errors (%d, numbers as #):" % len(kinds))
        for k in kinds:
            print("  " + k[:300])
    return 0 if rc == 0 and not found else 1


if __name__ == "__main__":
    sys.exit(main())
