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
  - the bed's mean void fraction below its top, same window;
  - the bed's height from the particles (particles.pvd frames, same window):
    twice the mean height of the particle centres above the floor (exact for
    a bed of uniform density), and the void fraction it implies,
    1 - V_particles / (A H).
Prints a table and, with --plot, draws dp against U with the buoyant weight
per area.
With --umf (runs at several U of one bed): the minimum fluidisation velocity
as Kunii & Levenspiel construct it, where the packed bed's line meets the
weight: the runs whose dp stays below 0.95 of the weight are fitted with
Ergun's form dp = a U + b U^2 (least squares), which is solved for dp =
weight; eps_mf is the bed's void fraction (from its height) in the fastest of
those runs. U_mf is compared with Wen & Yu's (1966) equation at that eps_mf,
Ar = 150 (1 - eps)/eps^3 Re + 1.75/eps^3 Re^2 (spheres; Ergun's equation set
equal to the buoyant weight, which is what their correlation's constants
approximate), and with their correlation Re = sqrt(33.7^2 + 0.0408 Ar) - 33.7.
With --heights PNG: the bed's height (twice the mean centre height) against
time, one line per run, to compare runs that oscillate (a slugging bed's
height swings by tens of per cent over a few tenths of a second, so a mean
over a short window depends on where in the swing it falls).
Usage: analyse_fbed.py [--from T] [--plot PNG] [--umf] [--heights PNG] label=folder [label=folder ...]
(the label names the run in the table; U is read from the scenario's inlet)."""
import argparse, collections, glob, json, math, os, re, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vti import read_vti, read_vtp  # noqa: E402


# One run's figures: U, mean dp, its sd, frames, layer eps, buoyant weight per
# area, label, bed height, eps from the height.
Run = collections.namedtuple("Run", "u dp sd frames eps weight label height eps_h")


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


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


def height_series(folder):
    """(t, 2 x the mean centre height) of every particle frame."""
    text = open(os.path.join(folder, "particles.pvd")).read()
    out = []
    for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text):
        zs = [p[2] for p in read_vtp(os.path.join(folder, f))["Points"]]
        out.append((float(t), 2 * sum(zs) / len(zs)))
    return out


def bed_height(series, t_from):
    """Mean over the particle frames from t_from of 2 x the mean centre height."""
    heights = [h for t, h in series if t >= t_from]
    return sum(heights) / len(heights) if heights else float("nan")


def minimum_fluidisation(rows, rho_f, mu, rho_p, d, g):
    packed = [r for r in rows if r.dp < 0.95 * r.weight]
    if len(packed) < 2:
        sys.exit("--umf: fewer than two runs below the weight")
    # dp / U = a + b U, least squares over the packed runs
    xs, ys = [r.u for r in packed], [r.dp / r.u for r in packed]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    a = my - b * mx
    w = packed[0].weight
    u_mf = (-a + math.sqrt(a * a + 4 * b * w)) / (2 * b) if b > 0 else w / a
    fastest = max(packed)
    eps = fastest.eps_h
    # Wen & Yu (1966) at eps_mf and their correlation: the formulas of
    # plugins/fluid/drag_laws.hpp (ergun_minimum_fluidisation_velocity,
    # wen_yu_minimum_fluidisation_velocity), which the CI test calls
    ar = rho_f * (rho_p - rho_f) * g * d ** 3 / mu ** 2
    qa, qb = 1.75 / eps ** 3, 150 * (1 - eps) / eps ** 3
    re = (-qb + math.sqrt(qb * qb + 4 * qa * ar)) / (2 * qa)
    u_wy = re * mu / (rho_f * d)
    u_corr = (math.sqrt(33.7 ** 2 + 0.0408 * ar) - 33.7) * mu / (rho_f * d)
    print()
    print(f"packed runs fitted: {n} (U = {', '.join(f'{x:g}' for x in xs)} m/s); dp = {a:.1f} U + {b:.1f} U^2 Pa")
    print(f"U_mf (fit meets the weight {w:.1f} Pa): {u_mf:.4f} m/s")
    print(f"eps_mf (bed height at U = {fastest.u:g} m/s): {eps:.4f}; Ar = {ar:.0f}")
    print(f"Wen-Yu at eps_mf: U_mf = {u_wy:.4f} m/s; domel / Wen-Yu = {u_mf / u_wy:.3f} ({100 * (u_mf / u_wy - 1):+.1f} %)")
    print(f"Wen-Yu's correlation (33.7, 0.0408): U_mf = {u_corr:.4f} m/s")
    return a, b, u_mf, u_wy


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--from", dest="t_from", type=float, default=0.3)
    ap.add_argument("--plot")
    ap.add_argument("--umf", action="store_true")
    ap.add_argument("--heights")
    ap.add_argument("runs", nargs="+")
    args = ap.parse_args()
    rows, all_series = [], []
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
        series = height_series(folder)
        all_series.append((label, series))
        height = bed_height(series, args.t_from)
        eps_h = 1 - n * math.pi * d ** 3 / 6 / (area * height)
        rows.append(Run(float(u), mean, sd, len(dps), sum(epss) / len(epss), weight, label, height, eps_h))
        props = (rho_f, mu, mat["density"], d, g)
    rows.sort()
    print("| run | U [m/s] | dp [Pa] (mean ± sd, frames) | dp / buoyant weight per area | bed eps (layers) "
          "| bed height [mm] | bed eps (height) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r.label} | {r.u:g} | {r.dp:.1f} ± {r.sd:.1f} ({r.frames}) | {r.dp / r.weight:.3f} | {r.eps:.3f} "
              f"| {1e3 * r.height:.1f} | {r.eps_h:.3f} |")
    umf = minimum_fluidisation(rows, *props) if args.umf else None
    if args.heights:
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 4))
        for label, series in all_series:
            ax.plot([t for t, _ in series], [1e3 * h for _, h in series], label=label)
        ax.axvline(args.t_from, color="k", ls=":", lw=0.8)
        ax.set_xlabel("simulated time [s]")
        ax.set_ylabel("bed height, 2 x mean centre height [mm]")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.heights, dpi=120)
    if args.plot:
        plt = pyplot()
        us = [r.u for r in rows]
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.errorbar(us, [r.dp for r in rows], yerr=[r.sd for r in rows], fmt="o", label="domel (vans, gidaspow)")
        ax.axhline(rows[0].weight, color="k", ls="--", label="buoyant weight / area")
        if umf:
            a, b, u_mf, u_wy = umf
            xs = [u_mf * i / 50 for i in range(51)]
            ax.plot(xs, [a * x + b * x * x for x in xs], "C0:", label=f"packed-bed fit, U_mf = {u_mf:.3f} m/s")
            ax.axvline(u_wy, color="C3", ls="-.", label=f"Wen-Yu at eps_mf: {u_wy:.3f} m/s")
        ax.set_xlabel("superficial gas velocity U [m/s]")
        ax.set_ylabel("bed pressure drop [Pa]")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
