#!/usr/bin/python3
"""The DCT chatter floor against the time step, on the collapse test (collapse_sd_vs_dct.json).

Writes, into a work folder, the collapse scenario with the `dct` model (mu_r = tan theta_c, theta_c = atan 0.1),
run for --duration seconds (default 4, the test's 1.5 s is too short for the floor to settle) at each --dt,
runs them with domel (--jobs at a time, one thread each, skipping finished runs), then prints, per window of
--window seconds from t = 1 s on, the mean over the window of the median |omega| of the particles at each dt,
the ratios between successive dt, and the exponent p of floor ~ dt^p between them (p = log(ratio)/log(dt ratio)).
With --plot PNG it plots the median |omega| against time for every dt (log scale).

Usage:
    scenarios/ab/dct_floor.py --work /tmp/dct_floor [--domel build/bin/domel] [--dt 1e-5 5e-6 2.5e-6]
                              [--duration 4] [--window 0.5] [--jobs 2] [--plot floor.png]
Exit status: 0, 1 when a run failed, 2 on bad usage.
"""

import argparse
import concurrent.futures
import csv
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
THETA_C = math.degrees(math.atan(0.1))


def write_scenario(work, dt, duration):
    with open(os.path.join(HERE, "collapse_sd_vs_dct.json")) as f:
        doc = json.load(f)
    name = "collapse_dct_dt%g" % dt
    doc.pop("$schema", None)
    doc["name"] = name
    doc["description"] = ("The collapse test of collapse_sd_vs_dct.json with the dct model (theta_c = atan 0.1) at "
                          "dt = %g s for %g s, written by scenarios/ab/dct_floor.py." % (dt, duration))
    sd = doc["subdomains"][0]
    sd["contact"]["rolling"] = {"model": "dct", "critical_angle": THETA_C}
    sd["time_step"] = dt
    doc["run"]["duration"] = duration
    doc["output"]["vtk_interval"] = 0
    doc["output"]["probe_interval"] = 0.01
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return name, path


def run(domel, work, name, path):
    out = os.path.join(work, "out_" + name)
    if os.path.isfile(os.path.join(out, "summary.json")):
        return name, 0
    env = {k: v for k, v in os.environ.items() if k != "DOMEL_PLUGIN_PATH"}
    with open(os.path.join(work, "log_" + name + ".txt"), "w") as log:
        rc = subprocess.call([domel, "run", path, "--out", out, "--overwrite", "--quiet", "--threads", "1"], stdout=log,
                             stderr=subprocess.STDOUT, env=env)
    return name, rc


def series(work, name):
    with open(os.path.join(work, "out_" + name, "probes.csv")) as f:
        rows = list(csv.DictReader(f))
    return [(float(r["time"]), float(r["heap.median_angular_speed"])) for r in rows]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--work", required=True, help="folder for the scenarios and the runs (kept; reruns are skipped)")
    ap.add_argument("--domel", default=os.path.join(os.path.dirname(os.path.dirname(HERE)), "build", "bin", "domel"))
    ap.add_argument("--dt", type=float, nargs="+", default=[1e-5, 5e-6, 2.5e-6], help="time steps, largest first")
    ap.add_argument("--duration", type=float, default=4.0)
    ap.add_argument("--window", type=float, default=0.5)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--plot", metavar="PNG")
    args = ap.parse_args(argv)
    if len(args.dt) < 2 or any(a <= b for a, b in zip(args.dt, args.dt[1:])):
        ap.error("--dt needs two or more time steps, largest first")
    if args.duration <= 1.0 + args.window:
        ap.error("--duration must leave at least one window after t = 1 s")
    os.makedirs(args.work, exist_ok=True)
    scen = [write_scenario(args.work, dt, args.duration) for dt in args.dt]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
        # longest runs (smallest dt) first
        failed = [n for n, rc in ex.map(lambda s: run(args.domel, args.work, *s), reversed(scen)) if rc != 0]
    if failed:
        print("dct_floor.py: failed: %s (see log_<name>.txt in %s)" % (", ".join(failed), args.work), file=sys.stderr)
        return 1
    data = {dt: series(args.work, name) for dt, (name, _) in zip(args.dt, scen)}
    windows = []
    t = 1.0
    while t + args.window <= args.duration + 1e-9:
        windows.append((t, t + args.window))
        t += args.window
    head = ["window [s]"] + ["dt = %g s" % dt for dt in args.dt]
    head += ["%g/%g: ratio, p" % (a, b) for a, b in zip(args.dt, args.dt[1:])]
    print("Mean over each window of the median |omega| of the particles [rad/s], and the floor's exponent p "
          "(floor ~ dt^p)")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for lo, hi in windows:
        means = []
        for dt in args.dt:
            vals = [w for t, w in data[dt] if lo - 1e-9 <= t <= hi + 1e-9]
            means.append(sum(vals) / len(vals) if vals else float("nan"))
        cells = ["%.3g–%.3g" % (lo, hi)] + ["%.3g" % m for m in means]
        for (a, ma), (b, mb) in zip(zip(args.dt, means), zip(args.dt[1:], means[1:])):
            ratio = mb / ma
            cells.append("%.2f, p = %.2f" % (ratio, math.log(ratio) / math.log(b / a)))
        print("| " + " | ".join(cells) + " |")
    if args.plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("dct_floor.py: matplotlib is missing (apt-get install python3-matplotlib)", file=sys.stderr)
            return 2
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for dt in args.dt:
            ts, ws = zip(*[(t, w) for t, w in data[dt] if t >= 0.5 and w > 0])
            ax.semilogy(ts, ws, label="dct, Δt = %g s" % dt, lw=1)
        ax.set_xlabel("time [s] (cylinder removed at 0.2 s)")
        ax.set_ylabel("median |ω| of the particles [rad/s]")
        ax.set_title("DCT chatter floor against the time step (collapse test)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print("wrote %s" % args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
