#!/usr/bin/python3
"""Plot benchmark CSVs written by bench/run_s1.py: throughput vs N, and vs threads.

Usage:
    /usr/bin/python3 bench/plot_results.py --out docs/performance CSV [CSV ...]

Writes <out>_vs_n.png (particle-steps/s per code and thread count against N, medians of the runs, min-max as error
bars) and <out>_vs_threads.png (domel's speed-up over its one-thread median per N, against the thread count, with
the ideal line). The title says which CSVs were used. Needs matplotlib (Debian: python3-matplotlib).
Exit status: 0 on success, 2 on bad usage or unreadable input.
"""

import argparse
import csv
import os
import statistics
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("plot_results.py: matplotlib is missing (apt-get install python3-matplotlib)", file=sys.stderr)
    sys.exit(2)


def load(paths):
    rows = []
    for p in paths:
        with open(p, newline="") as f:
            for r in csv.DictReader(f):
                if r.get("ok") != "1" or not r.get("particle_steps_per_s"):
                    continue
                rows.append({"code": r["code"], "n": int(r["N_actual"]), "rate": float(r["particle_steps_per_s"]),
                             "deck": os.path.basename(p).split("_2026")[0]})
    return rows


def threads_of(code):
    if code == "domel":
        return 1
    if code.startswith("domel_") and code.endswith("t"):
        return int(code[len("domel_"):-1])
    return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--out", required=True, help="output path prefix, e.g. docs/performance")
    args = ap.parse_args(argv)
    try:
        rows = load(args.csv)
    except OSError as e:
        print("plot_results.py: %s" % e, file=sys.stderr)
        return 2
    if not rows:
        print("plot_results.py: no successful runs in %s" % " ".join(args.csv), file=sys.stderr)
        return 2
    source = ", ".join(os.path.basename(p) for p in args.csv)

    groups = {}
    for r in rows:
        groups.setdefault((r["deck"], r["code"]), {}).setdefault(r["n"], []).append(r["rate"])

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for (deck, code), by_n in sorted(groups.items()):
        ns = sorted(by_n)
        med = [statistics.median(by_n[n]) for n in ns]
        lo = [m - min(by_n[n]) for m, n in zip(med, ns)]
        hi = [max(by_n[n]) - m for m, n in zip(med, ns)]
        label = "%s %s" % (deck, {"liggghts": "LIGGGHTS (serial)"}.get(code, code.replace("domel_", "domel ")))
        ax.errorbar(ns, med, yerr=[lo, hi], marker="o", capsize=3, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("particles N")
    ax.set_ylabel("particle-steps per second (timed steps)")
    ax.set_ylim(bottom=0)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Throughput vs N (median, min-max)\n" + source, fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out + "_vs_n.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.0, 4.5))
    max_t = 1
    for deck in sorted({d for d, _ in groups}):
        one = groups.get((deck, "domel"), {})
        for n in sorted(one):
            base = statistics.median(one[n])
            ts, sp = [], []
            for (d, code), by_n in groups.items():
                t = threads_of(code)
                if d != deck or t is None or n not in by_n:
                    continue
                ts.append(t)
                sp.append(statistics.median(by_n[n]) / base)
            if len(ts) < 2:
                continue
            order = sorted(range(len(ts)), key=lambda k: ts[k])
            ts = [ts[k] for k in order]
            sp = [sp[k] for k in order]
            max_t = max(max_t, ts[-1])
            ax.plot(ts, sp, marker="o", label="%s, N = %d" % (deck, n))
    ax.plot([1, max_t], [1, max_t], "k--", lw=0.8, label="ideal")
    ax.set_xlabel("domel threads")
    ax.set_ylabel("speed-up over domel on 1 thread")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Thread scaling (2-core VM)\n" + source, fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out + "_vs_threads.png", dpi=110)
    plt.close(fig)
    print("wrote %s_vs_n.png and %s_vs_threads.png" % (args.out, args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
