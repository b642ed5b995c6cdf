"""2D incremental projection SPH (ISPH) prototype with a surface mirror, for the sloshing free decay and
forced sway of the seed tank. Not part of the product: it measures whether a projection scheme can meet the
free-decay and forced-response bounds, as described in the manual's decisions page for the incompressible
scheme ("The projection prototype's surface shift").

The algorithm, one step:
  1. images: mirror images across the tank's walls, and across the free surface's height function eta(x)
     (pressure reversed there, so p = 0 on eta; velocity continued evenly);
  2. predictor: v* = v + dt (g - a_tank - G p / rho + nu L v), G the corrected difference gradient;
  3. pressure increment: L dp = rho/dt D v* + gamma (D G - L) p - beta rho (C - C0) / (C0 dt^2),
     solved directly (L the Morris Laplacian, D the corrected divergence, C the kernel sum);
  4. corrector: v = v* - dt G dp / rho, p += dp;
  5. shifting: dr = -(A h |v| dt + B h^2) grad C, the top layer's mean along the surface subtracted, capped
     at 0.2 dp, the pressure carried along it to first order; x += dt v + dr.

Usage (numpy and scipy):
  python3 isph.py decay --layers 24 [--dp 0.008] [--jitter 0.1] [--cycles 5]
  python3 isph.py rest --layers 24 --jitter 0.1 [--tend 3]
  python3 isph.py sway --layers 24 --ratio 0.8 [--amp 0.004]
"""
import argparse

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import curve_fit, least_squares
from scipy.spatial import cKDTree

G = 9.81
RHO = 1000.0
L_TANK = 0.8


class Sim:
    def __init__(s, layers, dp, dt=0.002, hfac=1.3, nu=1e-6, gamma=0.05, shift_a=2.0, shift_b=0.05,
                 surface_sigma=1.5, beta=0.003, jitter=0.0, seed=1, sway_a=0.0, sway_w=0.0, ramp=0.0):
        s.L, s.dp, s.h, s.dt = L_TANK, dp, hfac * dp, dt
        s.rc = 2.0 * s.h
        s.nu, s.gamma, s.A, s.B, s.sigma, s.beta = nu, gamma, shift_a, shift_b, surface_sigma, beta
        s.sway_a, s.sway_w, s.ramp = sway_a, sway_w, ramp
        s.detmin, s.wc = 0.25, 0.05
        nx = int(round(s.L / dp))
        X, Z = np.meshgrid((np.arange(nx) + 0.5) * dp, (np.arange(layers) + 0.5) * dp)
        s.x = np.stack([X.ravel(), Z.ravel()], 1)
        if jitter > 0:
            rng = np.random.default_rng(seed)
            s.x += rng.uniform(-jitter, jitter, s.x.shape) * dp
            s.x[:, 0] = np.clip(s.x[:, 0], 0.3 * dp, s.L - 0.3 * dp)
            s.x[:, 1] = np.maximum(s.x[:, 1], 0.3 * dp)
        s.n = len(s.x)
        s.depth = layers * dp
        s.v = np.zeros_like(s.x)
        s.p = RHO * G * np.maximum(s.depth - s.x[:, 1], 0.0)
        s.V = dp * dp
        s.t = 0.0
        s.acc = 0.0
        s.c0 = None
        s.alpha = 7.0 / (4.0 * np.pi * s.h ** 2)

    # Wendland C2 kernel (2D)
    def dwdr(s, r):
        q = r / s.h
        return s.alpha / s.h * (-5.0 * q) * np.clip(1.0 - 0.5 * q, 0, None) ** 3

    def w(s, r):
        q = r / s.h
        return s.alpha * np.clip(1.0 - 0.5 * q, 0, None) ** 4 * (2 * q + 1)

    def wall_images(s):
        x, rc, L = s.x, s.rc, s.L
        left, right, bot = x[:, 0] < rc, x[:, 0] > L - rc, x[:, 1] < rc
        pos, par, fx, fz = [], [], [], []
        for mask, func, flx, flz in [
            (left, lambda y: np.stack([-y[:, 0], y[:, 1]], 1), True, False),
            (right, lambda y: np.stack([2 * L - y[:, 0], y[:, 1]], 1), True, False),
            (bot, lambda y: np.stack([y[:, 0], -y[:, 1]], 1), False, True),
            (left & bot, lambda y: np.stack([-y[:, 0], -y[:, 1]], 1), True, True),
            (right & bot, lambda y: np.stack([2 * L - y[:, 0], -y[:, 1]], 1), True, True),
        ]:
            idx = np.nonzero(mask)[0]
            pos.append(func(x[idx]))
            par.append(idx)
            fx.append(np.full(len(idx), flx))
            fz.append(np.full(len(idx), flz))
        return np.concatenate(pos), np.concatenate(par), np.concatenate(fx), np.concatenate(fz)

    def height(s, xq):
        """eta(x): the highest particle within 0.75 dp, plus dp/2, Gaussian-smoothed over one spacing."""
        w = 0.5 * s.dp
        nb = int(np.ceil(s.L / w))
        idx = np.clip((s.x[:, 0] / w).astype(int), 0, nb - 1)
        top = np.full(nb, -np.inf)
        np.maximum.at(top, idx, s.x[:, 1])
        t2 = top.copy()
        t2[1:] = np.maximum(t2[1:], top[:-1])
        t2[:-1] = np.maximum(t2[:-1], top[1:])
        cen = (np.arange(nb) + 0.5) * w
        ok = np.isfinite(t2)
        t2 = np.interp(cen, cen[ok], t2[ok]) + 0.5 * s.dp
        k = np.arange(-4, 5)
        g = np.exp(-0.5 * (k / 2.0) ** 2)
        pad = np.concatenate([t2[4:0:-1], t2, t2[-2:-6:-1]])
        sm = np.convolve(pad, g / g.sum(), mode='valid')
        sm = np.maximum(sm, t2 - 0.25 * s.dp)
        xr = np.where(xq < 0, -xq, np.where(xq > s.L, 2 * s.L - xq, xq))
        return np.interp(xr, cen, sm)

    def neighbours(s):
        gx, gpar, gfx, gfz = s.wall_images()
        allx = np.concatenate([s.x, gx])
        s.par = np.concatenate([np.arange(s.n), gpar])
        s.flipx = np.concatenate([np.zeros(s.n, bool), gfx])
        s.flipz = np.concatenate([np.zeros(s.n, bool), gfz])
        s.nw = len(allx)
        # surface images of the particles and wall images within 2h of eta
        eta = s.height(allx[:, 0])
        s.depth_below = eta[:s.n] - s.x[:, 1]
        cand = np.nonzero(allx[:, 1] > eta - s.rc)[0]
        s.src = cand
        allx = np.concatenate([allx, np.stack([allx[cand, 0], 2 * eta[cand] - allx[cand, 1]], 1)])
        s.par = np.concatenate([s.par, s.par[cand]])
        s.flipx = np.concatenate([s.flipx, s.flipx[cand]])
        s.flipz = np.concatenate([s.flipz, s.flipz[cand]])
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
        M = np.zeros((s.n, 2, 2))
        for i in range(2):
            for j in range(2):
                M[:, i, j] = np.bincount(a, s.V * s.gw[:, i] * (-xab[:, j]), minlength=s.n)
        det = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
        Linv = np.zeros_like(M)
        Linv[:, 0, 0] = M[:, 1, 1]
        Linv[:, 1, 1] = M[:, 0, 0]
        Linv[:, 0, 1] = -M[:, 0, 1]
        Linv[:, 1, 0] = -M[:, 1, 0]
        ok = det > s.detmin
        Linv[ok] /= det[ok, None, None]
        Linv[~ok] = np.eye(2)
        s.cgw = np.einsum('pij,pj->pi', Linv[a], s.gw)
        s.ksum = np.bincount(a, s.V * s.w(r), minlength=s.n) + s.V * s.w(0.0)

    def image_vec(s, vec, noslip=False):
        """A vector field at every point: walls reflect it (free slip) or reverse it (no slip); the surface
        images carry their parent's value."""
        out = vec[s.par[:s.nw]].copy()
        if noslip:
            out[s.n:] = -out[s.n:]
        else:
            out[s.flipx[:s.nw], 0] *= -1
            out[s.flipz[:s.nw], 1] *= -1
        return np.concatenate([out, out[s.src]])

    def image_p(s, p):
        """Pressure at every point: continued with the body force's gradient across the walls, reversed
        across the surface."""
        nw = s.nw
        out = p[s.par[:nw]].copy()
        fz = s.flipz[:nw]
        out[fz] += RHO * G * (s.x[s.par[:nw][fz], 1] - s.allx[:nw][fz, 1])
        fx = s.flipx[:nw]
        out[fx] += -RHO * s.acc * (s.allx[:nw][fx, 0] - s.x[s.par[:nw][fx], 0])
        return np.concatenate([out, -out[s.src]])

    def grad(s, fall):
        df = (fall[s.b] - fall[s.a])[:, None] * s.cgw * s.V
        return np.stack([np.bincount(s.a, df[:, i], minlength=s.n) for i in range(2)], 1)

    def div(s, vall):
        dv = np.einsum('pi,pi->p', vall[s.b] - vall[s.a], s.cgw) * s.V
        return np.bincount(s.a, dv, minlength=s.n)

    def tank_pos(s, t):
        r = 1.0 if t >= s.ramp else 0.5 * (1.0 - np.cos(np.pi * t / s.ramp))
        return s.sway_a * r * np.sin(s.sway_w * t)

    def tank_acc(s, t):
        e = 1e-4
        return (s.tank_pos(t + e) - 2 * s.tank_pos(t) + s.tank_pos(t - e)) / e ** 2

    def surface_shift(s, sh):
        """Subtract from the top layer's shift its Gaussian-weighted mean along the layer (both components;
        images across the side walls, the x component odd there)."""
        near = np.nonzero(s.depth_below < s.dp)[0]
        xn, dn = s.x[near, 0], s.depth_below[near]
        sg = s.sigma * s.dp
        wd = np.exp(-0.5 * ((xn[:, None] - xn[None, :]) / sg) ** 2)
        wm = np.exp(-0.5 * ((xn[:, None] + xn[None, :]) / sg) ** 2)
        wm += np.exp(-0.5 * ((2 * s.L - xn[:, None] - xn[None, :]) / sg) ** 2)
        wz = np.exp(-0.5 * ((dn[:, None] - dn[None, :]) / (0.5 * s.dp)) ** 2)
        wgt = (wd + wm) * wz
        norm = wgt.sum(1)
        sh[near, 1] -= wgt @ sh[near, 1] / norm
        sh[near, 0] -= ((wd - wm) * wz) @ sh[near, 0] / norm

    def step(s):
        dt, n = s.dt, s.n
        s.acc = s.tank_acc(s.t + 0.5 * dt) if s.sway_a > 0 else 0.0
        body = np.array([-s.acc, -G])
        s.neighbours()
        a, b = s.a, s.b
        # predictor: body force, pressure, Morris viscosity with no-slip walls
        vall = s.image_vec(s.v, noslip=True)
        coef = 2.0 * s.V * s.fw / (s.r + 0.01 * s.h ** 2 / s.r)
        lapv = np.stack([np.bincount(a, coef * (vall[a, i] - vall[b, i]), minlength=n) for i in range(2)], 1)
        pall = s.image_p(s.p)
        gp = s.grad(pall)
        vs = s.v + dt * (body - gp / RHO + s.nu * lapv)
        rhs = RHO / dt * s.div(s.image_vec(vs))
        if s.beta > 0:
            if s.c0 is None:
                s.c0 = np.median(s.ksum)
            rhs = rhs - RHO * s.beta * (s.ksum - s.c0) / (s.c0 * dt * dt)
        # Morris Laplacian of the increment (wall images carry the parent's increment, surface images its
        # negative; a particle's own surface image couples to it)
        c = 2.0 * s.V * s.fw / (s.r ** 2 + 0.01 * s.h ** 2) * s.r
        pb = s.par[b]
        c_all = c
        c = np.where((pb == a) & (s.psign[b] > 0), 0.0, c)
        diag = np.bincount(a, c, minlength=n)
        A = sp.csr_matrix((np.concatenate([diag, -c * s.psign[b]]),
                           (np.concatenate([np.arange(n), a]), np.concatenate([np.arange(n), pb]))), shape=(n, n))
        if s.gamma > 0:
            # stabilisation of the collocated pressure: gamma (D G p - L p)
            e = body - gp / RHO
            dgp = -RHO * s.div(s.image_vec(e))
            lp = np.bincount(a, c_all * (pall[a] - pall[b]), minlength=n)
            rhs = rhs + s.gamma * (dgp - lp)
        dpres = spla.spsolve(A.tocsc(), rhs)
        s.p = s.p + dpres
        s.v = vs - dt / RHO * s.grad(dpres[s.par] * s.psign)
        # shifting
        dx = dt * s.v
        gc = np.stack([np.bincount(a, s.V * s.gw[:, i], minlength=n) for i in range(2)], 1)
        speed = np.linalg.norm(s.v, axis=1)
        sh = -(s.A * s.h * speed * dt + s.B * s.h * s.h)[:, None] * gc
        s.surface_shift(sh)
        mag = np.linalg.norm(sh, axis=1)
        sh *= np.minimum(1.0, 0.2 * s.dp / np.maximum(mag, 1e-30))[:, None]
        dx += sh
        s.p = s.p + np.sum(sh * s.grad(s.image_p(s.p)), 1)
        s.x += dx
        # keep particles inside the walls
        lo, hi = s.wc * s.dp, s.L - s.wc * s.dp
        m = (s.x[:, 0] < lo) & (s.v[:, 0] < 0) | (s.x[:, 0] > hi) & (s.v[:, 0] > 0)
        s.v[m, 0] = 0.0
        s.x[:, 0] = np.clip(s.x[:, 0], lo, hi)
        m = (s.x[:, 1] < lo) & (s.v[:, 1] < 0)
        s.v[m, 1] = 0.0
        s.x[:, 1] = np.maximum(s.x[:, 1], lo)
        s.t += dt

    def start_first_mode(s, amp):
        k = np.pi / s.L
        w = np.sqrt(G * k * np.tanh(k * s.depth))
        c = amp * w / (k * np.sinh(k * s.depth))
        xi, z = s.x[:, 0], s.x[:, 1]
        s.v[:, 0] = -c * k * np.sin(k * xi) * np.cosh(k * z)
        s.v[:, 1] = c * k * np.cos(k * xi) * np.sinh(k * z)
        return 2 * np.pi / w


def first_mode(depth):
    k = np.pi / L_TANK
    return np.sqrt(G * k * np.tanh(k * depth))


def fit_decay(t, y, T0):
    """Period and damping ratio of a decaying sinusoid with an offset."""
    t0, w0 = t[0], 2 * np.pi / T0

    def fn(tt, a, b, c, w, sg):
        u = tt - t0
        return np.exp(-sg * u) * (a * np.cos(w * u) + b * np.sin(w * u)) + c

    best = None
    for wg in np.linspace(0.9, 1.1, 9) * w0:
        try:
            popt, _ = curve_fit(fn, t, y, p0=[y[0], 0, 0, wg, 0.01], maxfev=20000)
        except RuntimeError:
            continue
        res = np.sum((fn(t, *popt) - y) ** 2)
        if best is None or res < best[0]:
            best = (res, popt)
    w, sg = best[1][3], best[1][4]
    return 2 * np.pi / w, sg / np.hypot(sg, w)


def faltinsen_sway_force(w, depth, mass, amp):
    """Linear potential theory (Faltinsen 1978): the force of the liquid on the tank, coefficient of sin wt,
    for a tank displacement amp sin wt."""
    total = 0.0
    for n in range(200):
        kn = (2 * n + 1) * np.pi / L_TANK
        wn2 = G * kn * np.tanh(kn * depth)
        total += 8 * np.tanh(kn * depth) * w ** 2 / (L_TANK ** 2 * depth * kn ** 3 * (wn2 - w ** 2))
    return mass * amp * w ** 2 * (1 + total)


def blew_up(s):
    speed = np.linalg.norm(s.v, axis=1)
    return not np.isfinite(speed).all() or speed.max() > 0.5


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('case', choices=['decay', 'rest', 'sway'])
    ap.add_argument('--layers', type=int, default=24)
    ap.add_argument('--dp', type=float, default=0.008)
    ap.add_argument('--jitter', type=float, default=0.0)
    ap.add_argument('--cycles', type=float, default=5.0)
    ap.add_argument('--tend', type=float, default=3.0)
    ap.add_argument('--ratio', type=float, default=0.8)
    ap.add_argument('--amp', type=float, default=None)
    a = ap.parse_args()
    if a.case == 'decay':
        s = Sim(a.layers, a.dp, jitter=a.jitter)
        s.neighbours()
        T = s.start_first_mode(0.01 if a.amp is None else a.amp)
        ts, ys = [], []
        for i in range(1, int(round(a.cycles * T / s.dt)) + 1):
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                break
            if i % 5 == 0:
                ts.append(s.t)
                ys.append(RHO * s.V * s.v[:, 0].sum())
        ts, ys = np.array(ts), np.array(ys)
        if len(ts) and ts[-1] > 4 * T:
            per, z = fit_decay(ts[ts >= T], ys[ts >= T], T)
            print(f"free decay: theory T {T:.4f} s; measured {per:.4f} s ({(per / T - 1) * 100:+.2f} %), "
                  f"damping ratio {z:.5f}")
    elif a.case == 'rest':
        s = Sim(a.layers, a.dp, jitter=a.jitter)
        s.neighbours()
        for i in range(1, int(round(a.tend / s.dt)) + 1):
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                break
            if i % 50 == 0:
                speed = np.linalg.norm(s.v, axis=1)
                print(f"t {s.t:.2f} s: mean speed {speed.mean():.2e} m/s, max {speed.max():.2e} m/s")
    else:
        amp = 0.004 if a.amp is None else a.amp
        w1 = first_mode(a.layers * a.dp)
        w = a.ratio * w1
        Tf, T1 = 2 * np.pi / w, 2 * np.pi / w1
        ramp = 2 * Tf
        s = Sim(a.layers, a.dp, jitter=a.jitter, sway_a=amp, sway_w=w, ramp=ramp)
        s.neighbours()
        mass = RHO * s.V * s.n
        ts, P = [], []
        while s.t < ramp + max(5 * Tf, 6 * T1):
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                return
            ts.append(s.t)
            P.append(RHO * s.V * s.v[:, 0].sum())
        ts, P = np.array(ts), np.array(P)
        F = -(np.gradient(P, ts) + mass * np.array([s.tank_acc(t) for t in ts]))
        m = ts > ramp
        t, f = ts[m], F[m]

        def res(q):
            u = t - t[0]
            return (q[0] * np.cos(w * t) + q[1] * np.sin(w * t)
                    + np.exp(-q[4] * u) * (q[2] * np.cos(q[5] * u) + q[3] * np.sin(q[5] * u)) - f)

        q = least_squares(res, [0, 0, 0, 0, 0.01, w1]).x
        got = np.hypot(q[0], q[1])
        phase = np.degrees(np.arctan2(q[0], q[1]))
        th = faltinsen_sway_force(w, a.layers * a.dp, mass, amp)
        dph = (phase - (0.0 if th > 0 else 180.0) + 180) % 360 - 180
        print(f"sway at {a.ratio} of the first mode: force per displacement {got / amp:.1f} N/m, theory "
              f"{abs(th) / amp:.1f} N/m ({(got / abs(th) - 1) * 100:+.1f} %), phase {dph:+.1f} deg")


if __name__ == '__main__':
    main()
