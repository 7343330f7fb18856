#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The timing table that .ci/run prints at its end.

usage: ci_times.py STEP LOG BUILD_DIR WALL_SECONDS [STEP LOG BUILD_DIR WALL_SECONDS ...]

For each step of CI (a scripts/test or scripts/sanitize call) LOG is what it
printed and BUILD_DIR the build tree its ctest ran in; WALL_SECONDS its
wall time. Prints, per step, its wall time, its build time (setup.sh's
"[setup] built in N s") and, per ctest label, the tests run, their summed
seconds (ctest's own per-test times: on two cores under ctest -j2 their sum
exceeds the wall time) and the longest test.
"""
import json
import re
import subprocess
import sys

TEST_LINE = re.compile(r"Test +#\d+: (\S+) .*?(Passed|\*\*\*Failed|Failed|\*\*\*Timeout|Not Run)\s+([0-9.]+) sec")


def labels_of(build_dir):
    try:
        out = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build_dir, capture_output=True, text=True).stdout
        tests = json.loads(out)["tests"]
    except (OSError, ValueError, KeyError):
        return {}
    labels = {}
    for t in tests:
        for p in t.get("properties", []):
            if p["name"] == "LABELS":
                labels[t["name"]] = p["value"]
    return labels


def minutes(s):
    return f"{int(s) // 60}:{int(s) % 60:02d}"


def main(argv):
    if len(argv) % 4 != 0 or not argv:
        print(__doc__, file=sys.stderr)
        return 64
    total = 0.0
    rows = []
    for k in range(0, len(argv), 4):
        step, log, build_dir, wall = argv[k], argv[k + 1], argv[k + 2], float(argv[k + 3])
        total += wall
        text = open(log, errors="replace").read()
        built = re.findall(r"\[setup\] built in (\d+) s", text)
        labels = labels_of(build_dir)
        per = {}
        for name, _, sec in TEST_LINE.findall(text):
            # a parameterised test's ctest name goes on after a space ("  # GetParam() = ...")
            labs = labels.get(name) or next((v for k, v in labels.items() if k.startswith(name + " ")), ["(none)"])
            for lab in labs:
                n, s, longest = per.get(lab, (0, 0.0, ("", 0.0)))
                per[lab] = (n + 1, s + float(sec), max(longest, (name, float(sec)), key=lambda x: x[1]))
        rows.append((step, wall, int(built[-1]) if built else None, per))
    print("\nCI times (wall m:s; tests: ctest's per-test seconds summed, several run at once under -j2)")
    print(f"{'step':28} {'wall':>7} {'build':>7}")
    for step, wall, built, _ in rows:
        print(f"{step:28} {minutes(wall):>7} {minutes(built) if built is not None else '-':>7}")
    print(f"{'total':28} {minutes(total):>7}")
    print(f"\n{'step':28} {'label':10} {'tests':>5} {'test s':>8}  longest")
    for step, _, _, per in rows:
        for lab in sorted(per):
            n, s, (name, sec) = per[lab]
            print(f"{step:28} {lab:10} {n:5d} {s:8.0f}  {name} ({sec:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
