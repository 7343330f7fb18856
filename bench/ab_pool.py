#!/usr/bin/env python3
"""Pools the timed runs of several bench/ab.py invocations of the same two binaries.

One ab.py invocation on this 2-vCPU VM resolves a 3 % difference only sometimes: the host switches between speed
regimes within minutes, and two invocations of the same pair of binaries have given new/old medians from 0.92 to
1.00 for the same case (docs/performance.md). This script reads every CSV given, keeps the timed rows, and per
case x N x threads prints

  - the medians of all old and all new runs pooled, and their ratio (the gate's number over all runs), and
  - the median of the paired ratios new/old, each pair being the old and new run of one rep of one invocation
    (ab.py runs them back to back, so a pair shares the host's regime), with the share of pairs in which new
    was faster and the 10th-90th percentiles of the paired ratios.

Every row of every file given is used: pass all the invocations of a session, not a chosen few.

Usage: python3 bench/ab_pool.py bench/results/ab_A.csv bench/results/ab_B.csv ...
Only the Python standard library is used.
"""

import csv
import statistics
import sys
from collections import defaultdict


def quantile(values, q):
    v = sorted(values)
    if not v:
        return float("nan")
    k = q * (len(v) - 1)
    lo = int(k)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def main(paths):
    if not paths:
        print(__doc__.strip().splitlines()[-2], file=sys.stderr)
        return 2
    runs = defaultdict(lambda: {"old": [], "new": []})
    pairs = defaultdict(dict)  # (case key) -> {(file, rep): {"old": v, "new": v}}
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row.get("mode") != "timed" or row.get("ok") != "1":
                    continue
                key = (row["case"], int(row["N_actual"]), int(row["threads"]))
                v = float(row["particle_steps_per_s"])
                runs[key][row["binary"]].append(v)
                pairs[key].setdefault((path, row["rep"]), {})[row["binary"]] = v
    print("| case | N | threads | runs old/new | old median | new median | new/old (pooled medians) | "
          "paired new/old: median [p10-p90] | pairs new faster | flag |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for key in sorted(runs):
        old, new = runs[key]["old"], runs[key]["new"]
        if not old or not new:
            continue
        ratio = statistics.median(new) / statistics.median(old)
        paired = [p["new"] / p["old"] for p in pairs[key].values() if "old" in p and "new" in p]
        faster = sum(1 for r in paired if r > 1)
        flag = "SLOWER>3%" if ratio < 0.97 else ""
        print(f"| {key[0]} | {key[1]} | {key[2]} | {len(old)}/{len(new)} | {statistics.median(old):.4g} | "
              f"{statistics.median(new):.4g} | {ratio:.3f} | {statistics.median(paired):.3f} "
              f"[{quantile(paired, 0.1):.3f}-{quantile(paired, 0.9):.3f}] | {faster}/{len(paired)} | {flag} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
