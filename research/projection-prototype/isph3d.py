"""3D projection SPH (ISPH) prototype: the 2D prototype's first configuration (`isph.py` with its defaults:
the free surface as a mirror across a height function, the pressure-increment scheme) in the 3D seed tank,
for the free decay, the forced sway and pitch of its first mode along the tank, and the tilted tank at rest.
Not part of the product: it measures whether the configuration that meets the free-decay and forced-response
bounds in 2D meets them in 3D at the spacings two cores can run in real time. The manual's decisions page for
the incompressible scheme ("The projection prototype in 3D", "The tilted tank at rest") gives what it
measures.

The step is `isph.py`'s, with the images in 3D:
  1. images: mirror images across the tank's five walls (a particle near an edge or a corner also has the
     images across two or three walls), and across the free surface z = eta(x, y) (pressure reversed there,
     velocity continued evenly; with --continued-surface a wall image's eta is moved by the body force's
     slope across the wall, as in 2D);
  2. predictor: v* = v + dt (f - G p / rho + nu L v), G the corrected difference gradient;
  3. pressure increment: L dp = rho/dt D v* + gamma (D G - L) p - beta rho (C - C0) / (C0 dt^2), solved
     by BiCGSTAB with a Jacobi preconditioner from zero (or the last increment, --warm-start) to a relative
     residual of 1e-8 unless --rtol says otherwise (SuperLU's direct solve, as in 2D, takes 50 times as long
     in 3D); gamma 0.05 is the 2D setting, and 3D needs 0.2 to survive a jittered start;
  4. corrector: v = v* - dt G dp / rho, p += dp;
  5. shifting: dr = -(A h |v| dt + B h^2) grad C, the top layer's mean along the surface subtracted, capped
     at 0.2 dp, the pressure carried along it to first order; x += dt v + dr.

Usage (numpy and scipy; the tank is 0.8 m long and round(0.25 m / dp) spacings broad):
  python3 isph3d.py decay --layers 20 [--dp 0.02] [--jitter 0.1] [--gamma 0.2] [--dt 0.004] [--rtol 1e-4]
  python3 isph3d.py sway --layers 20 --ratio 0.8 [--gamma 0.2] [--amp 0.004]
"""
import argparse
import itertools
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.interpolate import RegularGridInterpolator
from scipy.spatial import cKDTree

from isph import (G, L_TANK, RHO, Sim, blew_up, first_mode, fit_decay, forced_response, frame_force,
                  level_summary)

BREADTH = 0.25


class Sim3:
    def __init__(s, layers, dp, dt=0.004, hfac=1.3, nu=1e-6, gamma=0.05, shift_a=2.0, shift_b=0.05,
                 surface_sigma=1.5, beta=0.003, jitter=0.0, seed=1, sway_a=0.0, pitch_a=0.0, tilt=0.0,
                 tilt_ramp=0.0, forcing_w=0.0, ramp=0.0, wall_clearance=0.05, solve='bicgstab', rtol=1e-8,
                 warm_start=False, continued_surface=False):
        s.solve, s.rtol, s.iterations, s.warm_start, s.last_dp = solve, rtol, [], warm_start, None
        s.L, s.dp, s.h, s.dt = L_TANK, dp, hfac * dp, dt
        s.nx, s.ny = int(round(s.L / dp)), int(round(BREADTH / dp))
        s.B = s.ny * dp
        s.rc = 2.0 * s.h
        s.nu, s.gamma, s.A, s.Bs, s.sigma, s.beta = nu, gamma, shift_a, shift_b, surface_sigma, beta
        assert sway_a == 0.0 or pitch_a == 0.0, "sway or pitch, not both"
        s.sway_a, s.pitch_a, s.forcing_w, s.ramp = sway_a, pitch_a, forcing_w, ramp
        # a held pitch, reached from level under a half-cosine ramp of tilt_ramp seconds
        s.tilt, s.tilt_ramp = tilt, tilt_ramp
        s.detmin, s.wc = 0.25, wall_clearance
        # the free surface seen by a wall image: the height function continued evenly across the wall (as the
        # liquid's images are), or where the image's pressure, continued with the body force, is zero
        s.continued_surface = continued_surface
        k = np.arange(-4, 5) * dp
        KX, KY, KZ = np.meshgrid(k, k, k)
        X, Y, Z = np.meshgrid((np.arange(s.nx) + 0.5) * dp, (np.arange(s.ny) + 0.5) * dp,
                              (np.arange(layers) + 0.5) * dp, indexing='ij')
        s.x = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
        if jitter > 0:
            rng = np.random.default_rng(seed)
            s.x += rng.uniform(-jitter, jitter, s.x.shape) * dp
            s.x[:, 0] = np.clip(s.x[:, 0], 0.3 * dp, s.L - 0.3 * dp)
            s.x[:, 1] = np.clip(s.x[:, 1], 0.3 * dp, s.B - 0.3 * dp)
            s.x[:, 2] = np.maximum(s.x[:, 2], 0.3 * dp)
        s.n = len(s.x)
        s.depth = layers * dp
        s.v = np.zeros_like(s.x)
        s.p = RHO * G * np.maximum(s.depth - s.x[:, 2], 0.0)
        s.V = dp ** 3
        s.t = 0.0
        s.body = np.tile([0.0, 0.0, -G], (s.n, 1))
        s.c0 = None
        s.alpha = 21.0 / (16.0 * np.pi * s.h ** 3)
        s.cint = s.V * s.w(np.sqrt(KX ** 2 + KY ** 2 + KZ ** 2)).sum()

    # the Wendland C2 kernel's shape (its 3D factor is alpha), the forcing's time history and its rates, and
    # the sway's acceleration are the 2D script's
    dwdr, w, motion, motion_rates, tank_acc = Sim.dwdr, Sim.w, Sim.motion, Sim.motion_rates, Sim.tank_acc

    def wall_images(s):
        """Images across the walls x = 0, L, y = 0, B and the floor z = 0: every combination of the walls a
        particle is within 2h of (one, two at an edge, three at a corner)."""
        x, rc = s.x, s.rc
        choices = []
        for d, hi in [(0, s.L), (1, s.B)]:
            choices.append([(None, None), (x[:, d] < rc, 0.0), (x[:, d] > hi - rc, hi)])
        choices.append([(None, None), (x[:, 2] < rc, 0.0)])
        pos, par, flips = [], [], []
        for combo in itertools.product(*choices):
            if all(mask is None for mask, _ in combo):
                continue
            mask = np.ones(s.n, bool)
            for m, _ in combo:
                if m is not None:
                    mask &= m
            idx = np.nonzero(mask)[0]
            y = x[idx].copy()
            fl = np.zeros((len(idx), 3), bool)
            for d, (m, wall) in enumerate(combo):
                if m is not None:
                    y[:, d] = 2 * wall - y[:, d]
                    fl[:, d] = True
            pos.append(y)
            par.append(idx)
            flips.append(fl)
        return np.concatenate(pos), np.concatenate(par), np.concatenate(flips)

    def height(s, xq):
        """eta(x, y): the highest particle within 0.75 dp (in x and y), plus dp/2, Gaussian-smoothed over one
        spacing, continued evenly across the walls."""
        w = 0.5 * s.dp
        nbx, nby = int(np.ceil(s.L / w)), int(np.ceil(s.B / w))
        ix = np.clip((s.x[:, 0] / w).astype(int), 0, nbx - 1)
        iy = np.clip((s.x[:, 1] / w).astype(int), 0, nby - 1)
        top = np.full((nbx, nby), -np.inf)
        np.maximum.at(top, (ix, iy), s.x[:, 2])
        pad = np.pad(top, 1, constant_values=-np.inf)
        t2 = np.max([pad[1 + i:1 + i + nbx, 1 + j:1 + j + nby] for i in (-1, 0, 1) for j in (-1, 0, 1)], axis=0)
        ok = np.isfinite(t2)
        if not ok.all():
            # a column with no particle near it takes its nearest column's top
            cx, cy = np.nonzero(ok)
            _, near = cKDTree(np.stack([cx, cy], 1)).query(np.stack(np.nonzero(~ok), 1))
            t2[~ok] = t2[cx[near], cy[near]]
        t2 = t2 + 0.5 * s.dp
        k = np.arange(-4, 5)
        g = np.exp(-0.5 * (k / 2.0) ** 2)
        g /= g.sum()
        sm = np.pad(t2, 4, mode='reflect')
        sm = np.apply_along_axis(lambda c: np.convolve(c, g, mode='valid'), 0, sm)
        sm = np.apply_along_axis(lambda c: np.convolve(c, g, mode='valid'), 1, sm)
        sm = np.maximum(sm, t2 - 0.25 * s.dp)
        cx, cy = (np.arange(nbx) + 0.5) * w, (np.arange(nby) + 0.5) * w
        qx = np.where(xq[:, 0] < 0, -xq[:, 0], np.where(xq[:, 0] > s.L, 2 * s.L - xq[:, 0], xq[:, 0]))
        qy = np.where(xq[:, 1] < 0, -xq[:, 1], np.where(xq[:, 1] > s.B, 2 * s.B - xq[:, 1], xq[:, 1]))
        qx, qy = np.clip(qx, cx[0], cx[-1]), np.clip(qy, cy[0], cy[-1])
        return RegularGridInterpolator((cx, cy), sm)(np.stack([qx, qy], 1))

    def neighbours(s):
        gx, gpar, gfl = s.wall_images()
        allx = np.concatenate([s.x, gx])
        s.par = np.concatenate([np.arange(s.n), gpar])
        s.flip = np.concatenate([np.zeros((s.n, 3), bool), gfl])
        s.nw = len(allx)
        # images across the surface: every point within 2h below eta
        eta = s.height(allx)
        if s.continued_surface:
            # a wall image's pressure is its parent's plus rho f . (image - parent) (image_p): its surface is
            # where that is zero, the parent's surface moved by the body force's slope along the wall normal
            par = s.par[s.n:]
            for d in (0, 1):
                f = s.flip[s.n:, d]
                slope = s.body[par[f], d] / -s.body[par[f], 2]
                eta[s.n:][f] += slope * (allx[s.n:][f, d] - s.x[par[f], d])
        s.depth_below = eta[:s.n] - s.x[:, 2]
        cand = np.nonzero(allx[:, 2] > eta - s.rc)[0]
        img = allx[cand].copy()
        img[:, 2] = 2 * eta[cand] - img[:, 2]
        s.src = cand
        allx = np.concatenate([allx, img])
        s.par = np.concatenate([s.par, s.par[cand]])
        s.flip = np.concatenate([s.flip, s.flip[cand]])
        s.psign = np.concatenate([np.ones(s.nw), -np.ones(len(cand))])
        s.allx = allx
        d = cKDTree(s.x).sparse_distance_matrix(cKDTree(allx), s.rc, output_type='ndarray')
        a, b, r = d['i'], d['j'], d['v']
        keep = (a != b) & (r > 1e-12)
        s.a, s.b, s.r = a[keep], b[keep], r[keep]
        a, b, r = s.a, s.b, s.r
        xab = s.x[a] - allx[b]
        s.fw = s.dwdr(r)
        s.gw = (s.fw / r)[:, None] * xab
        # renormalisation of the gradient: M = sum V gradW (x_b - x_a)^T
        M = np.zeros((s.n, 3, 3))
        for i in range(3):
            for j in range(3):
                M[:, i, j] = np.bincount(a, s.V * s.gw[:, i] * (-xab[:, j]), minlength=s.n)
        det = np.linalg.det(M)
        Linv = np.tile(np.eye(3), (s.n, 1, 1))
        ok = det > s.detmin
        Linv[ok] = np.linalg.inv(M[ok])
        s.cgw = np.einsum('pij,pj->pi', Linv[a], s.gw)
        s.ksum = np.bincount(a, s.V * s.w(r), minlength=s.n) + s.V * s.w(0.0)

    def sums(s, per_pair):
        """The per-pair vectors summed onto each particle."""
        return np.stack([np.bincount(s.a, per_pair[:, i], minlength=s.n) for i in range(3)], 1)

    def image_vec(s, vec, noslip=False):
        """A vector field at every point: walls reflect it (free slip) or reverse it (no slip); the surface
        images carry their parent's value."""
        out = vec[s.par[:s.nw]].copy()
        if noslip:
            out[s.n:] = -out[s.n:]
        else:
            out[s.flip[:s.nw]] *= -1
        return np.concatenate([out, out[s.src]])

    def image_p(s, p):
        """Pressure at every point: continued with the body force's gradient across the walls, reversed
        across the surface."""
        nw = s.nw
        par = s.par[:nw]
        out = p[par].copy()
        for d in range(3):
            f = s.flip[:nw, d]
            out[f] += RHO * s.body[par[f], d] * (s.allx[:nw][f, d] - s.x[par[f], d])
        return np.concatenate([out, -out[s.src]])

    def grad(s, fall):
        return s.sums((fall[s.b] - fall[s.a])[:, None] * s.cgw * s.V)

    def div(s, vall):
        dv = np.einsum('pi,pi->p', vall[s.b] - vall[s.a], s.cgw) * s.V
        return np.bincount(s.a, dv, minlength=s.n)

    def body_force(s, t):
        """Force per unit mass on each particle in the tank frame: the 2D script's (`frame_force`), nothing
        along y."""
        if s.pitch_a == 0.0 and s.tilt == 0.0:
            return np.tile([-s.tank_acc(t), 0.0, -G], (s.n, 1))
        f = np.zeros((s.n, 3))
        f[:, 0], f[:, 2] = frame_force(s, t, s.x[:, 2], s.v[:, 0], s.v[:, 2])
        return f

    def surface_shift(s, sh):
        """Subtract from the top layer's shift its Gaussian-weighted mean along the layer (images across the
        side walls: the component normal to a wall odd there)."""
        near = np.nonzero(s.depth_below < s.dp)[0]
        xn, yn, dn = s.x[near, 0], s.x[near, 1], s.depth_below[near]
        sg = s.sigma * s.dp

        def gauss(u):
            return np.exp(-0.5 * (u / sg) ** 2)

        wx = [gauss(xn[:, None] - xn[None, :]), gauss(xn[:, None] + xn[None, :])
              + gauss(2 * s.L - xn[:, None] - xn[None, :])]
        wy = [gauss(yn[:, None] - yn[None, :]), gauss(yn[:, None] + yn[None, :])
              + gauss(2 * s.B - yn[:, None] - yn[None, :])]
        wz = np.exp(-0.5 * ((dn[:, None] - dn[None, :]) / (0.5 * s.dp)) ** 2)
        even = (wx[0] + wx[1]) * (wy[0] + wy[1]) * wz
        norm = even.sum(1)
        sh[near, 2] -= even @ sh[near, 2] / norm
        sh[near, 0] -= ((wx[0] - wx[1]) * (wy[0] + wy[1]) * wz) @ sh[near, 0] / norm
        sh[near, 1] -= ((wx[0] + wx[1]) * (wy[0] - wy[1]) * wz) @ sh[near, 1] / norm

    def step(s):
        dt, n = s.dt, s.n
        body = s.body = s.body_force(s.t + 0.5 * dt)
        s.neighbours()
        a, b = s.a, s.b
        # splash: a particle with too few neighbours, images included, keeps p = 0
        splash = s.ksum < 0.8 * s.cint
        s.p[splash] = 0.0
        # predictor: body force, pressure, Morris viscosity with no-slip walls
        vall = s.image_vec(s.v, noslip=True)
        coef = 2.0 * s.V * s.fw / (s.r + 0.01 * s.h ** 2 / s.r)
        lapv = s.sums(coef[:, None] * (vall[a] - vall[b]))
        pall = s.image_p(s.p)
        gp = s.grad(pall)
        vs = s.v + dt * (body - gp / RHO + s.nu * lapv)
        rhs = RHO / dt * s.div(s.image_vec(vs))
        if s.c0 is None:
            s.c0 = np.median(s.ksum)
        rhs = rhs - RHO * s.beta * (s.ksum - s.c0) / (s.c0 * dt * dt)
        # Morris Laplacian of the increment (wall images carry the parent's increment, surface images its
        # negative; a particle's own wall image couples to it trivially and is left out)
        c_all = 2.0 * s.V * s.fw / (s.r ** 2 + 0.01 * s.h ** 2) * s.r
        pb = s.par[b]
        c = np.where((pb == a) & (s.psign[b] > 0), 0.0, c_all)
        diag = np.bincount(a, c, minlength=n)
        A = sp.csr_matrix((np.concatenate([diag, -c * s.psign[b]]),
                           (np.concatenate([np.arange(n), a]), np.concatenate([np.arange(n), pb]))), shape=(n, n))
        # stabilisation of the collocated pressure: gamma (D G p - L p)
        dgp = -RHO * s.div(s.image_vec(body - gp / RHO))
        lp = np.bincount(a, c_all * (pall[a] - pall[b]), minlength=n)
        rhs = rhs + s.gamma * (dgp - lp)
        splash |= np.abs(diag) <= 1e-9 * np.abs(diag).max()
        if splash.any():
            A = sp.diags((~splash).astype(float)) @ A + sp.diags(splash.astype(float))
            rhs = np.where(splash, 0.0, rhs)
        if s.solve == 'direct':
            dpres = spla.spsolve(A.tocsc(), rhs)
        else:
            # BiCGSTAB with a Jacobi preconditioner, from zero or the last increment, as a particle code would
            # iterate (two products with the matrix an iteration)
            count = [0]

            def tick(_):
                count[0] += 1

            pre = sp.diags(1.0 / A.diagonal())
            x0 = s.last_dp if s.warm_start and s.last_dp is not None else None
            dpres, info = spla.bicgstab(A.tocsr(), rhs, x0=x0, rtol=s.rtol, atol=0.0, M=pre, maxiter=2000,
                                        callback=tick)
            s.last_dp = dpres
            assert info == 0, f"BiCGSTAB did not converge ({info})"
            s.iterations.append(count[0])
        s.p = s.p + dpres
        s.v = vs - dt / RHO * s.grad(dpres[s.par] * s.psign)
        # shifting
        dx = dt * s.v
        gc = s.sums(s.V * s.gw)
        speed = np.linalg.norm(s.v, axis=1)
        sh = -(s.A * s.h * speed * dt + s.Bs * s.h * s.h)[:, None] * gc
        s.surface_shift(sh)
        mag = np.linalg.norm(sh, axis=1)
        sh *= np.minimum(1.0, 0.2 * s.dp / np.maximum(mag, 1e-30))[:, None]
        dx += sh
        s.p = s.p + np.sum(sh * s.grad(s.image_p(s.p)), 1)
        s.x += dx
        # keep particles inside the walls
        lo = s.wc * s.dp
        for d, hi in [(0, s.L - lo), (1, s.B - lo), (2, np.inf)]:
            m = (s.x[:, d] < lo) & (s.v[:, d] < 0) | (s.x[:, d] > hi) & (s.v[:, d] > 0)
            s.v[m, d] = 0.0
            s.x[:, d] = np.clip(s.x[:, d], lo, hi)
        s.t += dt

    def level_error(s):
        """The height function's departure from the level surface of the tilted tank, over the columns more
        than a spacing from the walls."""
        g = np.arange(1.5, s.nx - 1) * s.dp
        gx, gy = np.meshgrid(g, np.arange(1.5, s.ny - 1) * s.dp, indexing='ij')
        q = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], 1)
        return s.height(q) - (s.depth + np.tan(s.tilt) * (q[:, 0] - 0.5 * s.L))

    def start_first_mode(s, amp):
        k = np.pi / s.L
        w = np.sqrt(G * k * np.tanh(k * s.depth))
        c = amp * w / (k * np.sinh(k * s.depth))
        xi, z = s.x[:, 0], s.x[:, 2]
        s.v[:, 0] = -c * k * np.sin(k * xi) * np.cosh(k * z)
        s.v[:, 2] = c * k * np.cos(k * xi) * np.sinh(k * z)
        return 2 * np.pi / w


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('case', choices=['decay', 'rest', 'sway', 'pitch'])
    ap.add_argument('--layers', type=int, default=20)
    ap.add_argument('--dp', type=float, default=0.02)
    ap.add_argument('--dt', type=float, default=0.004)
    ap.add_argument('--jitter', type=float, default=0.0)
    ap.add_argument('--cycles', type=float, default=5.0)
    ap.add_argument('--ratio', type=float, default=0.8)
    ap.add_argument('--amp', type=float, default=None)
    ap.add_argument('--tilt', type=float, default=5.0, help='rest: the tank\'s pitch, degrees')
    ap.add_argument('--ramp', type=float, default=5.0, help='rest: seconds to reach the tilt from level')
    ap.add_argument('--tend', type=float, default=8.0, help='rest: how long to run, seconds')
    ap.add_argument('--wall-clearance', type=float, default=0.05,
                    help='closest approach of a particle to a wall, in dp')
    ap.add_argument('--continued-surface', action='store_true',
                    help='a wall image\'s free surface is where its continued pressure is zero (not the even '
                         'continuation of the height function)')
    ap.add_argument('--gamma', type=float, default=0.05,
                    help='the pressure stabilisation\'s share of (D G - L) p (one less the memory)')
    ap.add_argument('--solve', choices=['direct', 'bicgstab'], default='bicgstab',
                    help='the pressure solve: direct, or BiCGSTAB (Jacobi-preconditioned) to --rtol')
    ap.add_argument('--rtol', type=float, default=1e-8, help='bicgstab: relative residual to stop at')
    ap.add_argument('--warm-start', action='store_true', help='bicgstab: start from the last step\'s increment')
    a = ap.parse_args()
    solve = dict(solve=a.solve, rtol=a.rtol, warm_start=a.warm_start, gamma=a.gamma,
                 continued_surface=a.continued_surface, wall_clearance=a.wall_clearance)
    start = time.time()
    if a.case == 'decay':
        s = Sim3(a.layers, a.dp, dt=a.dt, jitter=a.jitter, **solve)
        s.neighbours()
        T = s.start_first_mode(0.01 if a.amp is None else a.amp)
        ts, ys = [], []
        for i in range(1, int(round(a.cycles * T / s.dt)) + 1):
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                break
            if i % 2 == 0:
                ts.append(s.t)
                ys.append(RHO * s.V * s.v[:, 0].sum())
        ts, ys = np.array(ts), np.array(ys)
        if len(ts) and ts[-1] > 4 * T:
            per, z = fit_decay(ts[ts >= T], ys[ts >= T], T)
            print(f"3D free decay, {s.n} particles ({s.nx} x {s.ny} x {a.layers}): theory T {T:.4f} s; measured "
                  f"{per:.4f} s ({(per / T - 1) * 100:+.2f} %), damping ratio {z:.5f}")
    elif a.case == 'rest':
        s = Sim3(a.layers, a.dp, dt=a.dt, jitter=a.jitter, tilt=np.radians(a.tilt), tilt_ramp=a.ramp, **solve)
        s.neighbours()
        T1 = 2 * np.pi / first_mode(s.depth)
        held = []
        while s.t < a.tend - 1e-9:
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                return
            if s.t > a.tend - T1:
                dev = s.level_error()
                held.append((s.x[:, 0].mean() - 0.5 * s.L, s.x[:, 2].mean(), np.sqrt(np.mean(dev ** 2)),
                             np.abs(dev).max()))
        speed = np.linalg.norm(s.v, axis=1)
        print(f"3D {level_summary(s, np.array(held), T1)}; speed mean {speed.mean():.1e} m/s, largest "
              f"{speed.max():.1e} m/s")
    else:
        pitch = a.case == 'pitch'
        amp = (np.radians(0.5) if pitch else 0.004) if a.amp is None else a.amp
        w = a.ratio * first_mode(a.layers * a.dp)
        motion = dict(pitch_a=amp) if pitch else dict(sway_a=amp)
        s = Sim3(a.layers, a.dp, dt=a.dt, jitter=a.jitter, forcing_w=w, ramp=2 * 2 * np.pi / w, **motion, **solve)
        print(f"3D {forced_response(s, pitch, a.ratio, a.layers * a.dp, s.B)}")
    if s.iterations:
        it = np.array(s.iterations)
        print(f"BiCGSTAB to {a.rtol:g}: {it.mean():.1f} iterations a step (median {np.median(it):.0f}, "
              f"largest {it.max()})")
    print(f"wall time {time.time() - start:.0f} s")


if __name__ == '__main__':
    main()
