# Peer blue noise (blue-sampler 3.1.3 from PyPI, Python >= 3.12) written as
# varspec point files (columns set,x0,x1), one numpy seed per set.
#   python peer_blue_sampler.py N METHOD SETS OUT.csv
# METHOD: gaussian (exact GBN), nufft+, rgbn. See README.md, "Against the peer".
import sys, time, numpy as np, blue_sampler as b
n, method, sets, out = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4]
rows = []
t0 = time.time()
for s in range(sets):
    np.random.seed(1000 + s)
    p = np.asarray(b.sample_points(N=n, D=2, method=method, verbose=0), dtype=float)
    p = np.mod(p, 1.0)
    for x in p:
        rows.append((s, x[0], x[1]))
with open(out, "w") as f:
    f.write("set,x0,x1\n")
    for r in rows:
        f.write(f"{r[0]},{float(r[1])!r},{float(r[2])!r}\n")
print(f"{method} N={n} sets={sets}: {time.time()-t0:.1f} s", file=sys.stderr)
