"""The spectrum of one step of the projection prototypes' increment scheme with the particles frozen: the
linear map of (v, p) through the predictor, the increment's solve (with the pressure stabilisation's
gamma (D G - L) p) and the corrector, body forces, viscosity, the density term and the shifting left out.
Prints the largest eigenvalues' magnitudes (ARPACK) and where the leading mode's pressure peaks. The manual's
decisions page for the incompressible scheme ("The tilted tank at rest") gives what it found.

Usage (numpy and scipy; the state is the scripts' start, a lattice or a jittered one):
  python3 spectrum.py --dim 3 --dp 0.04 --layers 10 --jitter 0.1 --gamma 0.05 0.2
  python3 spectrum.py --dim 2 --dp 0.008 --layers 24 --jitter 0.1 --gamma 0.05 0.2
"""
import argparse

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from isph import Sim
from isph3d import Sim3


def operators(s, dim):
    """The corrected gradient G (dim n x n, row k n + a), the corrected divergence D (n x dim n) and the
    increment's Morris Laplacian A of the step, on each particle's own values (the images' parts that are
    linear in them: wall images carry their parent's pressure and reflected velocity, surface images the
    negated pressure)."""
    n, a, b = s.n, s.a, s.b
    pb = s.par[b]
    flip = s.flip if dim == 3 else np.stack([s.flipx, s.flipz], 1)
    gr, gc, gv, dr, dc, dv = [], [], [], [], [], []
    for k in range(dim):
        w = s.V * s.cgw[:, k]
        gr += [k * n + a, k * n + a]
        gc += [pb, a]
        gv += [w * s.psign[b], -w]
        dr += [a, a]
        dc += [k * n + pb, k * n + a]
        dv += [w * np.where(flip[b, k], -1.0, 1.0), -w]
    G = sp.csr_matrix((np.concatenate(gv), (np.concatenate(gr), np.concatenate(gc))), shape=(dim * n, n))
    D = sp.csr_matrix((np.concatenate(dv), (np.concatenate(dr), np.concatenate(dc))), shape=(n, dim * n))
    c = 2.0 * s.V * s.fw / (s.r ** 2 + 0.01 * s.h ** 2) * s.r
    c = np.where((pb == a) & (s.psign[b] > 0), 0.0, c)
    diag = np.bincount(a, c, minlength=n)
    A = sp.csr_matrix((np.concatenate([diag, -c * s.psign[b]]),
                       (np.concatenate([np.arange(n), a]), np.concatenate([np.arange(n), pb]))), shape=(n, n))
    return G, D, A


def step_map(s, dim, gamma):
    """One step on (v, P), P = dt p / rho: v* = v - G P; A dP = D v* + gamma (D G - A) P; P += dP;
    v = v* - G dP."""
    G, D, A = operators(s, dim)
    DG = (D @ G).tocsr()
    lu = spla.splu(A.tocsc())
    n = s.n

    def apply(x):
        v, P = x[:dim * n], x[dim * n:]
        vs = v - G @ P
        dP = lu.solve(D @ vs + gamma * (DG @ P)) - gamma * P
        return np.concatenate([vs - G @ dP, P + dP])

    return spla.LinearOperator(((dim + 1) * n, (dim + 1) * n), matvec=apply, dtype=float)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dim', type=int, choices=[2, 3], default=3)
    ap.add_argument('--dp', type=float, default=0.04)
    ap.add_argument('--layers', type=int, default=10)
    ap.add_argument('--jitter', type=float, default=0.1)
    ap.add_argument('--gamma', type=float, nargs='+', default=[0.05, 0.2])
    a = ap.parse_args()
    s = (Sim3 if a.dim == 3 else Sim)(a.layers, a.dp, jitter=a.jitter)
    s.neighbours()
    for g in a.gamma:
        vals, vecs = spla.eigs(step_map(s, a.dim, g), k=6, which='LM', tol=1e-8, maxiter=20000, ncv=80)
        order = np.argsort(-np.abs(vals))
        vals, lead = vals[order], np.abs(vecs[a.dim * s.n:, order[0]])
        peaks = '; '.join(f"x {s.x[i, 0] / a.dp:.1f} dp, {s.depth_below[i] / a.dp:.2f} dp deep"
                          for i in np.argsort(-lead)[:3])
        print(f"gamma {g}: largest |eigenvalue| " + ' '.join(f"{abs(v):.4f}" for v in vals[:4])
              + f"; the leading mode's pressure peaks at {peaks}")


if __name__ == '__main__':
    main()
