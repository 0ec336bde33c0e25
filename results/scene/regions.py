"""Where the dof scene's per-pixel variance lies, region by region.

Reads the maps `varspec render` writes (see README.md, "Where the variance
is"): var-{none,analytic}-{N}.npy and the analysis CSV of the same scene.
Regions come from the analysis (kind and depth) and, for the wall, from
its geometry: the wall is the plane at depth 8 = 2F, so a pixel's lens
rays reach world X = 2P - L, P on the pixel's square of side s on the
plane in focus and L on the lens of half-side A: X within 2P0 +- (s + A).
The wall's checker (period 0.8, cells centred on the origin) has its
boundaries at 0.2 + 0.4k; a wall pixel is "straight edge" when that range
holds a boundary along one axis, "corner" along both, "flat" along none.

For a straight-edge pixel the integrand is a step of contrast 0.7 in
t = x - (A/s)u (one axis), and no unbiased N-point rule with equal
weights does better than the step's position in t-measure stratified into
N strata: the count of points past the step takes the two integers
around N*W (W the measure past it), variance 0.49*q*(1 - q)/N^2 with
q = frac(N*W). The last column sums that bound over those pixels.

Usage: python3 regions.py FOLDER SPP [SPP ...]   (numpy)
"""
import csv
import math
import sys

import numpy as np

FOV_HALF = math.radians(20.0)
FOCUS, APERTURE, WIDTH = 4.0, 0.06, 256
PIXEL = 2.0 * FOCUS * math.tan(FOV_HALF) / WIDTH
REACH = PIXEL + APERTURE


def boundary(centre):
    """The checker boundary within the pixel's reach of `centre`, or None."""
    k = math.floor((centre - REACH - 0.2) / 0.4)
    hits = [0.2 + 0.4 * j for j in (k, k + 1, k + 2) if abs(0.2 + 0.4 * j - centre) <= REACH]
    return hits[0] if hits else None


def wall_point(row):
    """Where the pixel's centre ray meets the wall: 2 P0 (X, Y)."""
    px, py = int(row["px"]), int(row["py"])
    scale = math.tan(FOV_HALF) * FOCUS
    return (2.0 * ((px + 0.5) / (WIDTH / 2) - 1.0) * scale,
            2.0 * (1.0 - (py + 0.5) / (WIDTH / 2)) * scale)


def measure_past(tau):
    """W = P(x - k u < tau) for x, u uniform, k = A/s (midpoint rule in u)."""
    u = (np.arange(4096) + 0.5) / 4096
    return np.clip(tau + APERTURE / PIXEL * u, 0.0, 1.0).mean()


def step_bound(row, spp):
    """0.49 q(1 - q)/N^2 of a straight-edge pixel."""
    for centre in wall_point(row):
        b = boundary(centre)
        if b is not None:
            q = (spp * measure_past((b - centre + PIXEL - APERTURE) / (2.0 * PIXEL))) % 1.0
            return 0.49 * q * (1.0 - q) / spp**2
    raise ValueError("not a straight-edge pixel")


def region(row):
    if row["kind"] != "single":
        return "occlusion edge" if row["kind"] == "edge" else "background"
    depth = float(row["depth"])
    if depth < 3.0:
        return "sphere"
    if depth < 7.0:
        return "box"
    edges = sum(boundary(c) is not None for c in wall_point(row))
    return ["wall, flat", "wall, straight edge", "wall, corner"][edges]


def main(folder, spps):
    with open(f"{folder}/analysis.csv") as f:
        rows = list(csv.DictReader(f))
    names = [region(r) for r in rows]
    order = sorted(set(names), key=names.index)
    print("| spp | region | pixels | none | analytic warp | ratio | share of analytic | bound |")
    print("|---|---|---|---|---|---|---|---|")
    for spp in spps:
        none = np.load(f"{folder}/var-none-{spp}.npy").ravel()
        warp = np.load(f"{folder}/var-analytic-{spp}.npy").ravel()
        for name in order:
            m = np.array([n == name for n in names])
            a, b = none[m].sum() / none.size, warp[m].sum() / warp.size
            ratio = f"{a / b:.2f}" if b > 0 else "-"
            bound = "-"
            if name == "wall, straight edge":
                total = sum(step_bound(r, int(spp)) for r, n in zip(rows, names) if n == name)
                bound = f"{total / none.size:.3e}"
            print(f"| {spp} | {name} | {m.sum()} | {a:.3e} | {b:.3e} | {ratio} | {b / warp.mean():.2f} | {bound} |")
        print(f"| {spp} | all | {none.size} | {none.mean():.3e} | {warp.mean():.3e} | {none.mean() / warp.mean():.2f} | 1 | - |")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
