#!/usr/bin/env python3
"""Pressure drop across a gas-fluidised bed against the superficial velocity
(docs/validation/fluid.md, case c), from the fluid fields (fluid_*.vti) and
summary.json of runs at several inlet velocities.

For each run (an output folder of a scenario whose fluid block has a velocity
inlet on z_min and a pressure outlet on z_max):
  - below the bed: the last clear layer under it (a plenum under the DEM
    floor; best) or, when the bed starts in the first layer, the inlet face's
    pressure extrapolated from the two lowest layers (p0 + (p0 - p1)/2, crude
    when the bed is only a few layers tall); above the bed: the first clear
    layer over it (void fraction above 0.999); their difference less the
    gas's own hydrostatic rho_f g dz is the bed's pressure drop;
  - it is averaged over the frames from --from (default 0.3 s) to the end;
  - the bed's mean void fraction below its top, same window.
Prints a table and, with --plot, draws dp against U with the buoyant weight
per area and Ergun's fixed-bed line at the void fraction of the slowest run.
Usage: analyse_fbed.py [--from T] [--plot PNG] label=folder [label=folder ...]
(the label names the run in the table; U is read from the scenario's inlet)."""
import argparse, glob, json, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vti import read_vti  # noqa: E402


def layer_means(dims, arrays, name):
    nx, ny, nz = dims
    return [sum(arrays[name][i + nx * (j + ny * k)] for i in range(nx) for j in range(ny)) / (nx * ny)
            for k in range(nz)]


def frame_time(path):
    text = open(path, "rb").read(2000).decode("latin-1")
    i = text.index('Name="TimeValue"')
    j = text.index('RangeMin="', i) + len('RangeMin="')
    return float(text[j:text.index('"', j)])


def analyse(folder, t_from, rho_f, g):
    dps, epss = [], []
    for f in sorted(glob.glob(os.path.join(folder, "fluid_*.vti"))):
        if frame_time(f) < t_from:
            continue
        dims, origin, spacing, a = read_vti(f)
        p, e = layer_means(dims, a, "pressure"), layer_means(dims, a, "void_fraction")
        first = next((k for k in range(dims[2]) if e[k] <= 0.999), 0)
        top = next((k for k in range(first + 1, dims[2]) if e[k] > 0.999), dims[2] - 1)
        if first > 0:
            p_low, z_low = p[first - 1], origin[2] + (first - 0.5) * spacing[2]
        else:
            p_low, z_low = p[0] + 0.5 * (p[0] - p[1]), origin[2]
        z_top = origin[2] + (top + 0.5) * spacing[2]
        dps.append(p_low - p[top] - rho_f * g * (z_top - z_low))
        epss.append(sum(e[first:top]) / max(top - first, 1))
    return dps, epss


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--from", dest="t_from", type=float, default=0.3)
    ap.add_argument("--plot")
    ap.add_argument("runs", nargs="+")
    args = ap.parse_args()
    rows = []
    for spec in args.runs:
        label, folder = spec.split("=", 1)
        s = json.load(open(os.path.join(folder, "summary.json")))
        doc = json.load(open(s["scenario"]["file"]))
        fl = doc["fluid"]
        rho_f, mu = fl["density"], fl["viscosity"]
        g = abs(doc["gravity"][2])
        mat = doc["materials"][doc["subdomains"][0]["material"]]
        d = doc["subdomains"][0]["insert"][0]["diameter"] * doc["subdomains"][0].get("coarse_grain", 1)
        u = fl["boundaries"]["z_min"]["velocity"][2]
        n = s["particles"]
        lo, hi = fl["grid"]["min"], fl["grid"]["max"]
        area = (hi[0] - lo[0]) * (hi[1] - lo[1])
        weight = n * mat["density"] * math.pi * d ** 3 / 6 * g * (1 - rho_f / mat["density"]) / area
        dps, epss = analyse(folder, args.t_from, rho_f, g)
        mean = sum(dps) / len(dps)
        sd = math.sqrt(sum((x - mean) ** 2 for x in dps) / max(len(dps) - 1, 1))
        # the bed's height at the end from the state file: the 95th percentile
        # of the particles' tops above the lowest particle's bottom
        height = float("nan")
        state = s.get("outputs", {}).get("state", {})
        if state:
            zs, r0 = [], None
            for line in open(os.path.join(folder, list(state.values())[0])):
                if line.startswith("#") or line.startswith("id"):
                    continue
                f = line.split(",")
                zs.append((float(f[3]) + float(f[4]), float(f[3]) - float(f[4])))
            tops = sorted(z[0] for z in zs)
            height = tops[int(0.95 * (len(tops) - 1))] - min(z[1] for z in zs)
        rows.append((float(u), mean, sd, len(dps), sum(epss) / len(epss), weight, label, height))
    rows.sort()
    print("| run | U [m/s] | dp [Pa] (mean ± sd, frames) | dp / buoyant weight per area | bed eps (layers) | bed height at the end [mm] |")
    print("|---|---|---|---|---|---|")
    for u, mean, sd, nf, eps, w, label, height in rows:
        print(f"| {label} | {u:g} | {mean:.1f} ± {sd:.1f} ({nf}) | {mean / w:.3f} | {eps:.3f} | {1e3 * height:.1f} |")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        us = [r[0] for r in rows]
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.errorbar(us, [r[1] for r in rows], yerr=[r[2] for r in rows], fmt="o", label="domel (vans, gidaspow)")
        ax.axhline(rows[0][5], color="k", ls="--", label="buoyant weight / area")
        ax.set_xlabel("superficial gas velocity U [m/s]")
        ax.set_ylabel("bed pressure drop [Pa]")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
