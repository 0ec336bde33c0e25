"""What a per-pixel shear can gain at 16, 64 and 256 spp on the dof scene's
background, outside the renderer: a fronto-parallel checker (edges every
17.6 pixels, the 0.8 period at depth 8 through the 40-degree, 256-pixel
camera) seen through a square lens with light-field slope kappa = -5.275
pixels per unit of u (the centre depth's slope, `--analysis` CSV).

Unsheared: 4D uncorrelated multi-jitter, the pixel sees checker(x + kappa*u,
y + kappa*v). Sheared: the footprint warp sends the lens pattern's (u, v)
through the inverse CDF T^-1 of t = x + |kappa|*w, so the pixel sees
checker(T^-1(u), T^-1(v)) and x, y drop out. Variance over 64 realizations
per pixel, averaged over random checker offsets; then the sheared 16-spp
variance with other 16-point lens patterns (Owen-style scrambled Sobol',
shifted rank-1 lattices).

    python checker_bound.py        # numpy, scipy; a few minutes
"""
import numpy as np
from scipy.stats import qmc

KAPPA = 5.275  # |kappa|; the sign only mirrors u
HALF = 17.6    # checker square side in pixels


def multi_jitter(n, rng):
    """n*n points, one per grid cell and per 1/N column and row (Chiu et al. 1994)."""
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a, b = a.ravel(), b.ravel()
    col = np.array([rng.permutation(n) for _ in range(n)])  # per grid column
    row = np.array([rng.permutation(n) for _ in range(n)])  # per grid row
    x = (a + (col[a, b] + rng.random(n * n)) / n) / n
    y = (b + (row[b, a] + rng.random(n * n)) / n) / n
    return x, y


def inverse_cdf(u, k):
    """T^-1 for t = x + k*w, x and w uniform: a trapezoid on [0, 1 + k]."""
    a, b = min(1.0, k), max(1.0, k)
    ramp = a / (2 * b)
    return np.where(u < ramp, np.sqrt(2 * a * b * u),
                    np.where(u < 1 - ramp, b * u + 0.5 * a,
                             a + b - np.sqrt(2 * a * b * (1 - u))))


def checker(tx, ty, ox, oy):
    return (np.floor((tx + ox) / HALF) + np.floor((ty + oy) / HALF)) % 2


def mean_variance(estimate, offsets, realizations=64):
    return np.mean([np.var([estimate(ox, oy) for _ in range(realizations)])
                    for ox, oy in offsets])


rng = np.random.default_rng(2)
offsets = np.random.default_rng(9).random((300, 2)) * 2 * HALF
for n in (4, 8, 16):
    N = n * n

    def unsheared(ox, oy):
        x, y = multi_jitter(n, rng)
        u, v = multi_jitter(n, rng)
        p = rng.permutation(N)
        return checker(x + KAPPA * u[p], y + KAPPA * v[p], ox, oy).mean()

    def sheared(ox, oy):
        u, v = multi_jitter(n, rng)
        return checker(inverse_cdf(u, KAPPA), inverse_cdf(v, KAPPA), ox, oy).mean()

    vu, vs = mean_variance(unsheared, offsets), mean_variance(sheared, offsets)
    print(f"{N:4d} spp: unsheared {vu:.3e}, sheared {vs:.3e}, ratio {vu / vs:.2f}")


# One edge in the footprint (no corner): the pixel sees a step in t_x only.
def step(tx, ty, ox, oy):
    return ((tx + ox) % (2 * HALF) < HALF).astype(float)


def edge_unsheared(ox, oy):
    x, y = multi_jitter(4, rng)
    u, v = multi_jitter(4, rng)
    return step(x + KAPPA * u[rng.permutation(16)], y, ox, oy).mean()


def edge_sheared(ox, oy):
    u, v = multi_jitter(4, rng)
    return step(inverse_cdf(u, KAPPA), v, ox, oy).mean()


vu, vs = mean_variance(edge_unsheared, offsets), mean_variance(edge_sheared, offsets)
print(f"  16 spp, one edge: unsheared {vu:.3e}, sheared {vs:.3e}, ratio {vu / vs:.2f}")


def lens(pattern):
    def estimate(ox, oy):
        u, v = pattern()
        return checker(inverse_cdf(u, KAPPA), inverse_cdf(v, KAPPA), ox, oy).mean()
    return estimate


def sobol():
    p = qmc.Sobol(2, scramble=True, seed=rng).random(16)
    return p[:, 0], p[:, 1]


def lattice(g):
    def draw():
        i, s = np.arange(16), rng.random(2)
        return (i / 16 + s[0]) % 1, (i * g / 16 + s[1]) % 1
    return draw


for name, pattern in [("multi-jitter", lambda: multi_jitter(4, rng)),
                      ("scrambled Sobol'", sobol),
                      ("lattice (1, 3)", lattice(3)),
                      ("lattice (1, 5)", lattice(5)),
                      ("lattice (1, 7)", lattice(7))]:
    print(f"16 spp, sheared, lens {name}: {mean_variance(lens(pattern), offsets):.3e}")
