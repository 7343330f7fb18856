#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Do two builds of domel write the same outputs? The gate for changes that
must not change behaviour (a refactoring; issue 40 item 9).

usage: scripts/same_outputs.py OLD_DOMEL NEW_DOMEL [--steps N] [--work DIR]
                               [--only SUBSTRING ...] [--threads T]

Runs every scenario under scenarios/ (or those whose path contains one of
the --only substrings) with both executables, on T threads (default 1),
for N macro steps (default 200; --max-steps) with output.state switched on,
and compares the two output folders file by file: every file byte for byte
(state CSVs, probes.csv, balance and grid files, VTK frames, checkpoints
are not written by these runs), and summary.json with the values that
measure the machine rather than the run taken out (wall times, rates,
memory, dates, plugin paths). Prints one line per scenario and the files
that differ; exit 1 when any does.

Each executable finds its plugins as usual (its build tree's plugins/); an
old build copied elsewhere keeps its plugins beside it (DIR/bin/domel and
DIR/plugins/). OLD's outputs are kept in WORK/old and reused by later calls
with the same OLD, N and T (a file WORK/old/<case>/.done records them).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# summary.json keys whose values measure the machine or the moment, not the run
VOLATILE = {"finished", "wall_time_s", "particle_steps_per_s", "peak_rss_bytes", "plugin_libraries",
            "timed_window", "seconds", "timing", "wall_s", "plugin_seconds"}


def scrub(j):
    if isinstance(j, dict):
        return {k: scrub(v) for k, v in j.items() if k not in VOLATILE and "seconds" not in k}
    if isinstance(j, list):
        return [scrub(v) for v in j]
    return j


def scenarios(only):
    found = []
    for base, _, files in os.walk(os.path.join(ROOT, "scenarios")):
        for f in files:
            if f.endswith(".json") and not f.startswith(".same_outputs_"):
                path = os.path.join(base, f)
                rel = os.path.relpath(path, os.path.join(ROOT, "scenarios"))
                if not only or any(o in rel for o in only):
                    found.append(rel)
    return sorted(found)


def run(domel, rel, out, steps, threads):
    src = os.path.join(ROOT, "scenarios", rel)
    with open(src) as f:
        doc = json.load(f)
    doc.setdefault("output", {})["state"] = True
    # beside the original, so that its relative paths (meshes, initial states) hold
    tmp = os.path.join(os.path.dirname(src), ".same_outputs_" + os.path.basename(src))
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1)
    try:
        t0 = time.time()
        r = subprocess.run([domel, "run", tmp, "--out", out, "--max-steps", str(steps), "--threads", str(threads),
                            "--quiet", "--overwrite"], capture_output=True, text=True)
        return r, time.time() - t0
    finally:
        os.remove(tmp)


def files_of(folder):
    out = {}
    for base, _, files in os.walk(folder):
        for f in files:
            if f.startswith("."):
                continue
            p = os.path.join(base, f)
            out[os.path.relpath(p, folder)] = p
    return out


def differences(a, b):
    fa, fb = files_of(a), files_of(b)
    diffs = [f"only in old: {k}" for k in sorted(set(fa) - set(fb))]
    diffs += [f"only in new: {k}" for k in sorted(set(fb) - set(fa))]
    for k in sorted(set(fa) & set(fb)):
        if k == "summary.json":
            ja, jb = scrub(json.load(open(fa[k]))), scrub(json.load(open(fb[k])))
            ja.get("scenario", {}).pop("file", None)
            jb.get("scenario", {}).pop("file", None)
            if ja != jb:
                keys = sorted(x for x in set(ja) | set(jb) if ja.get(x) != jb.get(x))
                diffs.append(f"summary.json differs at {keys}")
        else:
            with open(fa[k], "rb") as x, open(fb[k], "rb") as y:
                if x.read() != y.read():
                    diffs.append(f"differs: {k}")
    return diffs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--work", default="/tmp/domel_same_outputs")
    ap.add_argument("--only", nargs="*", default=[])
    a = ap.parse_args()
    old, new = os.path.abspath(a.old), os.path.abspath(a.new)
    stamp = f"{old} {a.steps} {a.threads}"
    bad = 0
    for rel in scenarios(a.only):
        case = rel.replace("/", "_")[:-5]
        o_dir, n_dir = os.path.join(a.work, "old", case), os.path.join(a.work, "new", case)
        done = os.path.join(o_dir, ".done")
        t_old = 0.0
        if not (os.path.exists(done) and open(done).read() == stamp):
            shutil.rmtree(o_dir, ignore_errors=True)
            r, t_old = run(old, rel, o_dir, a.steps, a.threads)
            with open(done if r.returncode == 0 else os.path.join(a.work, ".junk"), "w") as f:
                f.write(stamp)
            if r.returncode != 0:
                print(f"{rel}: OLD failed: {r.stderr[-400:]}", flush=True)
        shutil.rmtree(n_dir, ignore_errors=True)
        r, t_new = run(new, rel, n_dir, a.steps, a.threads)
        if r.returncode != 0:
            bad += 1
            print(f"{rel}: NEW failed: {r.stderr[-400:]}", flush=True)
            continue
        d = differences(o_dir, n_dir)
        bad += bool(d)
        print(f"{rel}: {'same' if not d else 'DIFFERENT'} ({t_old:.1f} s / {t_new:.1f} s)", flush=True)
        for x in d[:12]:
            print("   ", x, flush=True)
    print("all the same" if not bad else f"{bad} scenario(s) differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
