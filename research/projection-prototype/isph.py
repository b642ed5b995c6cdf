"""2D projection SPH (ISPH) prototype with a surface mirror, for the sloshing free decay, forced sway and
pitch of the seed tank and a dam break. Not part of the product: it measures whether a projection scheme can
meet the free-decay and forced-response bounds, as described in the manual's decisions page for the
incompressible scheme ("The projection prototype's surface shift" and the sections after it).

The algorithm, one step:
  1. images: mirror images across the tank's walls, and across the free surface (pressure reversed there,
     so p = 0 on it; velocity continued evenly). The surface is a height function eta(x) (`--surface
     height`) or, at each point, the tangent plane averaged from the nearby surface particles (`plane`); a
     wall image's height function is its parent's, or with `--continued-surface` moved by the body force's
     slope across the wall, to where the image's continued pressure is zero;
  2. predictor: v* = v + dt (f - G p / rho + nu L v), f the body force in the tank frame, G the corrected
     difference gradient;
  3. pressure increment: L dp = rho/dt D v* + gamma (D G - L) p - beta rho (C - C0) / (C0 dt^2),
     solved directly (L the Morris Laplacian, D the corrected divergence, C the kernel sum). With
     `--pressure total` the whole pressure is solved for instead (no G p in v*), with -memory (D G - L) p
     from the old pressure in place of the gamma term: memory 1 - gamma is the same scheme;
  4. corrector: v = v* - dt G dp / rho, p += dp. Three guards for impacts (off by default): where the kernel
     sum exceeds the rest value by 5-15 % the conservative gradient sum V (p_a + p_b) grad W is blended in
     (`--conservative-blend`); splash particles keep v* (`--ballistic-splash`); pairs closer than a share of
     dp that approach each other lose half their approach speed (`--collide`);
  5. shifting: dr = -(A h |v| dt + B h^2) grad C, the top layer's mean along the surface subtracted, capped
     at 0.2 dp, the pressure carried along it to first order; x += dt v + dr.

Usage (numpy and scipy):
  python3 isph.py decay --layers 24 [--dp 0.008] [--jitter 0.1] [--cycles 5]
  python3 isph.py rest --layers 24 --jitter 0.1 [--tend 3]
  python3 isph.py rest --layers 24 --tilt 5 --tend 8 [--ramp 5] [--continued-surface]
  python3 isph.py sway --layers 24 --ratio 0.8 [--amp 0.004]
  python3 isph.py pitch --layers 24 --ratio 0.8 [--amp 0.0087]
  python3 isph.py dambreak --surface plane --wall-clearance 0.5 [--validation DIR]
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
    def __init__(s, layers, dp, length=L_TANK, dt=0.002, hfac=1.3, nu=1e-6, gamma=0.05, shift_a=2.0, shift_b=0.05,
                 surface_sigma=1.5, beta=0.003, jitter=0.0, seed=1, sway_a=0.0, pitch_a=0.0, forcing_w=0.0, ramp=0.0,
                 surface='height', wall_clearance=0.05, pressure='increment', memory=0.95, memory_depth=0.0,
                 memory_top=0.0, memory_clip=0.0, blend=(0.0, 0.0), ballistic_splash=False, collide=0.0,
                 tilt=0.0, tilt_ramp=0.0, continued_surface=False):
        s.L, s.dp, s.h, s.dt = length, dp, hfac * dp, dt
        s.rc = 2.0 * s.h
        s.nu, s.gamma, s.A, s.B, s.sigma, s.beta = nu, gamma, shift_a, shift_b, surface_sigma, beta
        assert sway_a == 0.0 or pitch_a == 0.0, "sway or pitch, not both"
        s.sway_a, s.pitch_a, s.forcing_w, s.ramp = sway_a, pitch_a, forcing_w, ramp
        # a held pitch, reached from level under a half-cosine ramp of tilt_ramp seconds
        s.tilt, s.tilt_ramp = tilt, tilt_ramp
        # the free surface seen by a wall image: the height function continued evenly across the wall (as the
        # liquid's images are), or where the image's pressure, continued with the body force, is zero
        s.continued_surface = continued_surface
        s.detmin, s.wc = 0.25, wall_clearance
        s.surface = surface
        # pressure 'total': solve for the whole pressure, carrying `memory` of the old pressure's mismatch
        # between D G and L (memory 1 - gamma is the increment scheme's), only deeper than memory_depth dp
        s.total = pressure == 'total'
        if s.total:
            s.gamma = -memory
        s.memory_depth = memory_depth
        s.memory_top = memory_top  # the memory carried above memory_depth
        s.memory_clip = memory_clip  # each particle's memory term at most this many rho g / dp (0: no limit)
        # impact guards: the conservative gradient blended in from blend[0] to blend[1] times the rest kernel
        # sum (0: off); splash particles move ballistically; approaching pairs closer than collide dp collide
        assert blend[1] == 0.0 or s.total, "the conservative blend acts on the whole pressure"
        s.blend_lo, s.blend_hi = blend
        s.ballistic_splash, s.collide = ballistic_splash, collide
        # tangent-plane surface: a particle whose kernel sum (liquid and wall images) is below surf_thr of the
        # lattice's is a surface particle; points and normals are averaged over plane_sigma dp; the surface is
        # at least dmin dp above a point; an image closer than img_clear dp to a particle is dropped; a particle
        # whose kernel sum with images is below splash_thr of the lattice's keeps p = 0
        s.surf_thr, s.plane_sigma, s.dmin, s.img_clear, s.splash_thr = 0.88, 1.0, 0.5, 0.6, 0.8
        k = np.arange(-4, 5) * dp
        KX, KZ = np.meshgrid(k, k)
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
        s.body = np.tile([0.0, -G], (s.n, 1))
        s.c0 = None
        s.alpha = 7.0 / (4.0 * np.pi * s.h ** 2)
        s.cint = s.V * s.w(np.hypot(KX, KZ)).sum()

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

    def height_images(s, allx):
        """Images across the height function: every point within 2h below eta(x)."""
        eta = s.height(allx[:, 0])
        if s.continued_surface:
            # a wall image's pressure is its parent's plus rho f . (image - parent) (image_p): its surface is
            # where that is zero, the parent's surface moved by the body force's slope along the wall normal
            par = s.par[s.n:s.nw]
            f = s.flipx[s.n:s.nw]
            eta[s.n:][f] += s.body[par[f], 0] / -s.body[par[f], 1] * (allx[s.n:][f, 0] - s.x[par[f], 0])
        s.depth_below = eta[:s.n] - s.x[:, 1]
        cand = np.nonzero(allx[:, 1] > eta - s.rc)[0]
        return cand, np.stack([allx[cand, 0], 2 * eta[cand] - allx[cand, 1]], 1)

    def plane_images(s, allx):
        """Images across each point's tangent plane: the Gaussian-weighted mean, over the surface particles
        (and their wall images) within 2h, of the surface points x + n dp/2 and of the smoothed normals."""
        liquid = cKDTree(s.x)
        d = liquid.sparse_distance_matrix(cKDTree(allx), s.rc, output_type='ndarray')
        a, b, r = d['i'], d['j'], d['v']
        keep = (a != b) & (r > 1e-12)
        a, b, r = a[keep], b[keep], r[keep]
        gw = (s.dwdr(r) / r)[:, None] * (s.x[a] - allx[b])
        gc = np.stack([np.bincount(a, s.V * gw[:, i], minlength=s.n) for i in range(2)], 1)
        ks = np.bincount(a, s.V * s.w(r), minlength=s.n) + s.V * s.w(0.0)
        gn = np.linalg.norm(gc, axis=1)
        nrm = -gc / np.maximum(gn, 1e-30)[:, None]
        nrm[gn < 1e-6 / s.h] = [0.0, 1.0]
        sidx = np.nonzero((ks < s.surf_thr * s.cint)[s.par])[0]
        sx = allx[sidx]
        sn = nrm[s.par[sidx]].copy()
        sn[s.flipx[sidx], 0] *= -1
        sn[s.flipz[sidx], 1] *= -1
        sg = s.plane_sigma * s.dp
        st = cKDTree(sx)
        dd = st.sparse_distance_matrix(st, s.rc, output_type='ndarray')
        wgt = np.exp(-0.5 * (dd['v'] / sg) ** 2)
        ns = np.stack([np.bincount(dd['i'], wgt * sn[dd['j'], k], minlength=len(sx)) for k in range(2)], 1)
        ns /= np.maximum(np.linalg.norm(ns, axis=1), 1e-30)[:, None]
        q = sx + 0.5 * s.dp * ns
        d = cKDTree(allx).sparse_distance_matrix(st, s.rc, output_type='ndarray')
        i, j = d['i'], d['j']
        wgt = np.exp(-0.5 * (d['v'] / sg) ** 2)
        wsum = np.bincount(i, wgt, minlength=s.nw)
        has = wsum > 0
        qi = np.stack([np.bincount(i, wgt * q[j, k], minlength=s.nw) for k in range(2)], 1)
        ni = np.stack([np.bincount(i, wgt * ns[j, k], minlength=s.nw) for k in range(2)], 1)
        qi[has] /= wsum[has, None]
        ni[has] /= np.maximum(np.linalg.norm(ni[has], axis=1), 1e-30)[:, None]
        dist = np.full(s.nw, np.inf)
        dist[has] = np.einsum('pi,pi->p', qi[has] - allx[has], ni[has])
        dist = np.maximum(dist, s.dmin * s.dp)
        s.depth_below = dist[:s.n]
        cand = np.nonzero(dist < s.rc)[0]
        img = allx[cand] + 2 * dist[cand, None] * ni[cand]
        # an image that lands among the liquid (its plane taken from a surface elsewhere) is dropped
        gap, _ = liquid.query(img)
        ok = gap > s.img_clear * s.dp
        return cand[ok], img[ok]

    def neighbours(s):
        gx, gpar, gfx, gfz = s.wall_images()
        allx = np.concatenate([s.x, gx])
        s.par = np.concatenate([np.arange(s.n), gpar])
        s.flipx = np.concatenate([np.zeros(s.n, bool), gfx])
        s.flipz = np.concatenate([np.zeros(s.n, bool), gfz])
        s.nw = len(allx)
        cand, img = s.height_images(allx) if s.surface == 'height' else s.plane_images(allx)
        s.src = cand
        allx = np.concatenate([allx, img])
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
        out[fz] += RHO * s.body[s.par[:nw][fz], 1] * (s.allx[:nw][fz, 1] - s.x[s.par[:nw][fz], 1])
        fx = s.flipx[:nw]
        out[fx] += RHO * s.body[s.par[:nw][fx], 0] * (s.allx[:nw][fx, 0] - s.x[s.par[:nw][fx], 0])
        return np.concatenate([out, -out[s.src]])

    def grad(s, fall):
        df = (fall[s.b] - fall[s.a])[:, None] * s.cgw * s.V
        return np.stack([np.bincount(s.a, df[:, i], minlength=s.n) for i in range(2)], 1)

    def div(s, vall):
        dv = np.einsum('pi,pi->p', vall[s.b] - vall[s.a], s.cgw) * s.V
        return np.bincount(s.a, dv, minlength=s.n)

    def motion(s, t):
        """The forcing's time history per unit amplitude: sin wt under a half-cosine ramp."""
        r = 1.0 if t >= s.ramp else 0.5 * (1.0 - np.cos(np.pi * t / s.ramp))
        return r * np.sin(s.forcing_w * t)

    def motion_rates(s, t):
        """The motion's first and second time derivatives (central differences)."""
        e = 1e-4
        m0, mp, mm = s.motion(t), s.motion(t + e), s.motion(t - e)
        return (mp - mm) / (2 * e), (mp - 2 * m0 + mm) / e ** 2

    def tank_acc(s, t):
        return s.sway_a * s.motion_rates(t)[1] if s.sway_a > 0 else 0.0

    def body_force(s, t):
        """Force per unit mass on each particle in the tank frame (`frame_force`)."""
        f = np.empty((s.n, 2))
        f[:, 0], f[:, 1] = frame_force(s, t, s.x[:, 1], s.v[:, 0], s.v[:, 1])
        return f

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
        if s.surface == 'plane':
            # the layer need not be a graph of x: neighbours along it are near in z too
            zn = s.x[near, 1]
            wz *= np.exp(-0.5 * ((zn[:, None] - zn[None, :]) / sg) ** 2)
        wgt = (wd + wm) * wz
        norm = wgt.sum(1)
        sh[near, 1] -= wgt @ sh[near, 1] / norm
        sh[near, 0] -= ((wd - wm) * wz) @ sh[near, 0] / norm

    def collisions(s):
        """Pairs of liquid particles closer than collide dp that approach each other lose half their relative
        normal speed, shared equally: momentum is kept and energy lost."""
        own = (s.b < s.n) & (s.a < s.b) & (s.r < s.collide * s.dp)
        ca, cb = s.a[own], s.b[own]
        nab = (s.x[ca] - s.x[cb]) / s.r[own][:, None]
        vn = np.einsum('pi,pi->p', s.v[ca] - s.v[cb], nab)
        app = vn < 0
        imp = 0.25 * vn[app][:, None] * nab[app]
        ca, cb = ca[app], cb[app]
        for k in range(2):
            s.v[:, k] += np.bincount(cb, imp[:, k], minlength=s.n) - np.bincount(ca, imp[:, k], minlength=s.n)

    def step(s):
        dt, n = s.dt, s.n
        body = s.body = s.body_force(s.t + 0.5 * dt)
        s.neighbours()
        a, b = s.a, s.b
        # splash: a particle with too few neighbours, images included, keeps p = 0
        splash = s.ksum < s.splash_thr * s.cint
        s.p[splash] = 0.0
        # predictor: body force, pressure, Morris viscosity with no-slip walls
        vall = s.image_vec(s.v, noslip=True)
        coef = 2.0 * s.V * s.fw / (s.r + 0.01 * s.h ** 2 / s.r)
        lapv = np.stack([np.bincount(a, coef * (vall[a, i] - vall[b, i]), minlength=n) for i in range(2)], 1)
        pall = s.image_p(s.p)
        gp = s.grad(pall)
        if s.total:
            # the whole pressure is solved for: the walls' images carry the predictor's body-force part
            # unreflected, so that the hydrostatic pressure (continued across the walls) is the solution at rest
            vs = s.v + dt * (body + s.nu * lapv)
            vimg = s.image_vec(s.v + dt * s.nu * lapv) + dt * body[s.par]
            rhs = RHO / dt * s.div(vimg)
        else:
            vs = s.v + dt * (body - gp / RHO + s.nu * lapv)
            rhs = RHO / dt * s.div(s.image_vec(vs))
        if s.c0 is None:
            s.c0 = np.median(s.ksum)
        if s.beta > 0:
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
        if s.total:
            # the images' pressure is affine in their parent's: the constant part goes to the right-hand side
            rhs = rhs + np.bincount(a, c_all * s.image_p(np.zeros(n))[b], minlength=n)
        if s.gamma != 0:
            # stabilisation of the collocated pressure: gamma (D G p - L p)
            e = body - gp / RHO
            dgp = -RHO * s.div(s.image_vec(e))
            lp = np.bincount(a, c_all * (pall[a] - pall[b]), minlength=n)
            gam = np.where(s.depth_below < s.memory_depth * s.dp, -s.memory_top, s.gamma)
            term = gam * (dgp - lp)
            if s.memory_clip > 0:
                # a pressure spike's memory is cut to what a smooth pressure needs
                lim = s.memory_clip * RHO * G / s.dp
                term = np.clip(term, -lim, lim)
            rhs = rhs + term
        splash |= np.abs(diag) <= 1e-9 * np.abs(diag).max()
        if splash.any():
            A = sp.diags((~splash).astype(float)) @ A + sp.diags(splash.astype(float))
            rhs = np.where(splash, 0.0, rhs)
        dpres = spla.spsolve(A.tocsc(), rhs)
        if s.total:
            s.p = dpres
            pall = s.image_p(s.p)
            gp = s.grad(pall)
            if s.blend_hi > 0:
                # where particles crowd together: the corrected gradient is not the divergence's adjoint, and
                # a collapse can gain energy through it; the conservative form, sum V (p_a + p_b) grad W, is
                # the plain difference divergence's negative adjoint and pushes a crowded particle apart
                df = (pall[b] + pall[a])[:, None] * s.gw * s.V
                gsym = np.stack([np.bincount(a, df[:, i], minlength=n) for i in range(2)], 1)
                th = np.clip((s.ksum / s.c0 - s.blend_lo) / (s.blend_hi - s.blend_lo), 0.0, 1.0)[:, None]
                gp = (1.0 - th) * gp + th * gsym
            s.v = vs - dt / RHO * gp
        else:
            s.p = s.p + dpres
            s.v = vs - dt / RHO * s.grad(dpres[s.par] * s.psign)
        if s.ballistic_splash:
            # a splash particle's neighbourhood is too sparse for a renormalised gradient: it flies free
            s.v[splash] = vs[splash]
        if s.collide > 0:
            s.collisions()
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


def frame_force(s, t, z, vx, vz):
    """The x and z components of the force per unit mass in the tank frame, for particles at height z (and
    x = s.x[:, 0]) moving at (vx, vz): gravity, the sway's inertial force, and the pitch's (theta about +y
    through the centre of the floor; positive theta turns the apparent gravity towards +x): Euler
    -theta'' y x r, Coriolis -2 theta' y x v, centrifugal theta'^2 r. A held tilt is added to theta; its ramp
    is slow enough to leave out its rates."""
    m, rate, accel = (s.motion(t), *s.motion_rates(t)) if s.pitch_a != 0.0 else (0.0, 0.0, 0.0)
    share = 1.0 if t >= s.tilt_ramp else 0.5 * (1.0 - np.cos(np.pi * t / s.tilt_ramp))
    th, thd, thdd = s.tilt * share + s.pitch_a * m, s.pitch_a * rate, s.pitch_a * accel
    xr = s.x[:, 0] - 0.5 * s.L
    fx = G * np.sin(th) - s.tank_acc(t) - thdd * z - 2 * thd * vz + thd ** 2 * xr
    fz = -G * np.cos(th) + thdd * xr + 2 * thd * vx + thd ** 2 * z
    return fx, fz


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


def pitch_moment(w, depth, modes=400):
    """Linear potential theory (Faltinsen & Timokha 2009): the liquid's moment about y on the tank, about the
    centre of the floor, per unit breadth, coefficient of sin wt for a pitch theta_a sin wt (per unit
    theta_a). The same series as the solver's sloshing::theory::Tank::pitch_moment."""
    L, h, g = L_TANK, depth, G
    c, w2 = h / 2.0, w * w
    inertia = L * h ** 3 / 3.0 - h * L ** 3 / 12.0
    surface = 0.0
    for i in range(modes):
        k = (2 * i + 1) * np.pi / L
        wn2 = g * k * np.tanh(k * h)
        e = -4.0 / (L * k * k)
        bc = 8.0 / (L * k ** 3)
        bs = bc * np.tanh(k * c)
        a = (w2 * (h * e + bs) + g * e) / (wn2 - w2)
        sech = 1.0 / np.cosh(k * h) if k * h < 700.0 else 0.0  # (cosh overflows past 710)
        inertia += -4.0 * bc * (c / k - np.tanh(k * c) / (k * k)) + 4.0 * bs / (k * k)
        inertia += -2.0 * a * (h * np.tanh(k * h) / k - (1.0 - sech) / (k * k)) + 2.0 * a * (1.0 - sech) / (k * k)
        surface += -2.0 * a * np.tanh(k * h) / k
    return RHO * (g * (L * h * h / 2.0 + surface) + w2 * inertia)


def fit_forced(t, f, w, w1):
    """Amplitude and phase (degrees, of the sin wt coefficient) of a response at w, fitted together with a
    decaying free mode near w1."""
    def res(q):
        u = t - t[0]
        return (q[0] * np.cos(w * t) + q[1] * np.sin(w * t)
                + np.exp(-q[4] * u) * (q[2] * np.cos(q[5] * u) + q[3] * np.sin(q[5] * u)) - f)

    q = least_squares(res, [0, 0, 0, 0, 0.01, w1]).x
    return np.hypot(q[0], q[1]), np.degrees(np.arctan2(q[0], q[1]))


def level_summary(s, held, T1):
    """The tilted tank at rest, averaged over the last first-mode period (rows of held: centroid x from the
    floor's centre, centroid z, rms and largest departure of the surface from the level plane): the weight's
    moment about y through the centre of the floor against that of the level liquid in the tilted box."""
    th, slope, h0, L = s.tilt, np.tan(s.tilt), s.depth, s.L
    xc, zc = slope * L ** 2 / (12 * h0), h0 / 2 + slope ** 2 * L ** 2 / (24 * h0)
    xm, zm = held[:, 0].mean(), held[:, 1].mean()
    moment, m_th = zm * np.sin(th) + xm * np.cos(th), zc * np.sin(th) + xc * np.cos(th)
    return (f"tank tilted {np.degrees(th):g} deg at rest, {s.n} particles (last {T1:.2f} s): surface from the "
            f"level plane rms {held[:, 2].mean() / s.dp:.3f} dp, largest {held[:, 3].max() / s.dp:.3f} dp; "
            f"centroid x {xm * 1000:.2f} mm (theory {xc * 1000:.2f}), z {zm * 1000:.2f} mm "
            f"(theory {zc * 1000:.2f}); the weight's moment about the floor's centre "
            f"{(moment / m_th - 1) * 100:+.2f} % from theory")


def forced_response(s, pitch, ratio, depth, breadth=1.0):
    """Runs a forced sway or pitch (the simulation set up with its amplitude, frequency and ramp of two
    forcing periods) to five forcing periods or six natural ones after the ramp, whichever is longer, and
    says how the liquid's force or moment on the tank, fitted at the forcing frequency, compares with linear
    theory (per unit breadth, times `breadth` in 3D)."""
    amp, w = (s.pitch_a if pitch else s.sway_a), s.forcing_w
    w1 = first_mode(depth)
    zi = s.x.shape[1] - 1
    mass = RHO * s.V * s.n
    s.neighbours()
    ts, P, Ly, tb, Mb = [], [], [], [], []
    while s.t < s.ramp + max(5 * 2 * np.pi / w, 6 * 2 * np.pi / w1):
        xb, zb = s.x[:, 0] - 0.5 * s.L, s.x[:, zi].copy()
        s.step()
        if blew_up(s):
            return f"blew up at {s.t:.3f} s"
        # moments about the centre of the floor, y component of r x (.)
        tb.append(s.t - 0.5 * s.dt)
        Mb.append(RHO * s.V * np.sum(zb * s.body[:, 0] - xb * s.body[:, zi]))
        xr, z = s.x[:, 0] - 0.5 * s.L, s.x[:, zi]
        ts.append(s.t)
        P.append(RHO * s.V * s.v[:, 0].sum())
        Ly.append(RHO * s.V * np.sum(z * s.v[:, 0] - xr * s.v[:, zi]))
    ts, P, Ly = np.array(ts), np.array(P), np.array(Ly)
    if pitch:
        # the liquid's moment on the tank: its body forces' moment less the rate of its angular momentum
        resp = np.interp(ts, tb, Mb) - np.gradient(Ly, ts)
        th = pitch_moment(w, depth) * breadth * amp
        what, unit = "moment per rotation", "N m/rad"
    else:
        # (Faltinsen's solution per unit breadth with the liquid's whole mass is the solution times the breadth)
        resp = -(np.gradient(P, ts) + mass * np.array([s.tank_acc(t) for t in ts]))
        th = faltinsen_sway_force(w, depth, mass, amp)
        what, unit = "force per displacement", "N/m"
    m = ts > s.ramp
    got, phase = fit_forced(ts[m], resp[m], w, w1)
    dph = (phase - (0.0 if th > 0 else 180.0) + 180) % 360 - 180
    return (f"{'pitch' if pitch else 'sway'} at {ratio} of the first mode, {s.n} particles: {what} "
            f"{got / amp:.1f} {unit}, theory {abs(th) / amp:.1f} {unit} ({(got / abs(th) - 1) * 100:+.1f} %), "
            f"phase {dph:+.1f} deg")


def blew_up(s):
    speed = np.linalg.norm(s.v, axis=1)
    return not np.isfinite(speed).all() or speed.max() > 0.5


def dam_break(n, tend, kw, validation, width=0.146):
    """Koshizuka & Oka (1996): a column width wide and twice as high at the left end of a tank four widths
    long. Prints the surge front (the furthest particle within 2 dp of the floor with three neighbours) against
    T = t sqrt(2 g / width), beside the experiment and their MPS computation when the validation folder
    (holding dambreak_front/koshizuka_oka_1996_*.csv) is given."""
    dp = width / n
    s = Sim(2, dp, length=4 * width, **kw)
    X, Z = np.meshgrid((np.arange(n) + 0.5) * dp, (np.arange(2 * n) + 0.5) * dp)
    s.x = np.stack([X.ravel(), Z.ravel()], 1)
    s.n = len(s.x)
    s.v = np.zeros_like(s.x)
    s.p = RHO * G * (2 * width - s.x[:, 1])
    s.depth = 2 * width
    s.dt = 0.4 * s.h / (2 * np.sqrt(G * 2 * width))
    s.neighbours()
    scale = np.sqrt(2 * G / width)
    ts, zs = [], []

    def energy():
        return np.sum(0.5 * np.sum(s.v ** 2, 1) + G * s.x[:, 1])

    # the energy that can be lost: the column's potential energy above the level liquid's (depth width / 2)
    e0, report = energy(), 1.0
    e_free = e0 - s.n * G * width / 4
    # a closed tank cannot gain mechanical energy: the largest rise over the lowest earlier value
    e_low, rise, rise_at = e0, 0.0, 0.0
    while s.t * scale < tend:
        s.step()
        if not np.isfinite(s.v).all():
            print(f"blew up at T = {s.t * scale:.2f}")
            break
        e = energy()
        e_low = min(e_low, e)
        if e - e_low > rise:
            rise, rise_at = e - e_low, s.t * scale
        if s.t * scale >= report:
            speed = np.linalg.norm(s.v, axis=1)
            print(f"T {s.t * scale:.1f}: energy lost {(e0 - e) / e_free * 100:.1f} % of the available, "
                  f"fastest particle {speed.max():.2f} m/s, {np.sum(speed > 4.0)} faster than 4 m/s")
            report += 1.0
        own = s.b < s.n
        count = np.bincount(s.a[own], minlength=s.n)
        m = (s.x[:, 1] < 2 * dp) & (count >= 3)
        ts.append(s.t * scale)
        zs.append(s.x[m, 0].max() / width if m.any() else np.nan)
    print(f"largest energy rise over an earlier value: {rise / e_free * 100:.1f} % of the available "
          f"(T {rise_at:.1f})")
    ts, zs = np.array(ts), np.array(zs)
    refs = {}
    if validation:
        for name in ['experiment', 'mps']:
            refs[name] = np.loadtxt(f"{validation}/dambreak_front/koshizuka_oka_1996_{name}.csv", delimiter=',',
                                    skiprows=1)
    for T in [0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8]:
        if T <= ts[-1]:
            front = np.interp(T, ts, zs)
            line = f"T {T:.1f}: front Z/L {front:.3f}"
            for name, ref in refs.items():
                z = np.interp(T, ref[:, 0], ref[:, 1])
                line += f"; {name} {z:.3f} ({(front / z - 1) * 100:+.1f} %)"
            print(line)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('case', choices=['decay', 'rest', 'sway', 'pitch', 'dambreak'])
    ap.add_argument('--layers', type=int, default=24)
    ap.add_argument('--dp', type=float, default=0.008)
    ap.add_argument('--jitter', type=float, default=0.0)
    ap.add_argument('--cycles', type=float, default=5.0)
    ap.add_argument('--tend', type=float, default=3.0)
    ap.add_argument('--gamma', type=float, default=0.05,
                    help='increment: the pressure stabilisation\'s share of (D G - L) p')
    ap.add_argument('--shift-a', type=float, default=2.0, help='shifting: the velocity-scaled coefficient A')
    ap.add_argument('--shift-b', type=float, default=0.05, help='shifting: the fixed coefficient B')
    ap.add_argument('--tilt', type=float, default=0.0, help='rest: the tank\'s held pitch, degrees')
    ap.add_argument('--ramp', type=float, default=5.0, help='rest: seconds to reach the tilt from level')
    ap.add_argument('--continued-surface', action='store_true',
                    help='height surface: a wall image\'s free surface is where its continued pressure is zero '
                         '(not the even continuation of the height function)')
    ap.add_argument('--ratio', type=float, default=0.8)
    ap.add_argument('--amp', type=float, default=None)
    ap.add_argument('--surface', choices=['height', 'plane'], default='height',
                    help='free surface: a height function eta(x), or each point\'s tangent plane')
    ap.add_argument('--wall-clearance', type=float, default=0.05,
                    help='closest approach of a particle to a wall, in dp')
    ap.add_argument('--pressure', choices=['increment', 'total'], default='increment',
                    help='solve for the pressure increment (gamma stabilisation) or the whole pressure')
    ap.add_argument('--memory', type=float, default=0.95,
                    help='total: share of the old pressure\'s (D G - L) mismatch carried into the solve')
    ap.add_argument('--memory-depth', type=float, default=0.0,
                    help='total: carry it only for particles deeper than this (dp) below the surface')
    ap.add_argument('--memory-top', type=float, default=0.0,
                    help='total: the share carried above --memory-depth')
    ap.add_argument('--memory-clip', type=float, default=0.0,
                    help='total: cut each particle\'s memory term to this many rho g / dp (0: no limit)')
    ap.add_argument('--conservative-blend', type=float, nargs=2, default=(0.0, 0.0), metavar=('FROM', 'TO'),
                    help='total: blend in the conservative gradient from FROM to TO times the rest kernel sum')
    ap.add_argument('--ballistic-splash', action='store_true', help='splash particles take no pressure force')
    ap.add_argument('--collide', type=float, default=0.0,
                    help='approaching pairs closer than this (dp) lose half their approach speed (0: off)')
    ap.add_argument('--column', type=int, default=25, help='dambreak: particles across the column')
    ap.add_argument('--validation', default=None, help='dambreak: the validation data folder, for comparison')
    a = ap.parse_args()
    kw = dict(surface=a.surface, wall_clearance=a.wall_clearance, pressure=a.pressure, memory=a.memory,
              memory_depth=a.memory_depth, memory_top=a.memory_top, memory_clip=a.memory_clip,
              blend=tuple(a.conservative_blend), ballistic_splash=a.ballistic_splash, collide=a.collide,
              continued_surface=a.continued_surface, gamma=a.gamma, shift_a=a.shift_a, shift_b=a.shift_b)
    if a.case == 'dambreak':
        dam_break(a.column, a.tend, kw, a.validation)
        return
    if a.case == 'decay':
        s = Sim(a.layers, a.dp, jitter=a.jitter, **kw)
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
        s = Sim(a.layers, a.dp, jitter=a.jitter, tilt=np.radians(a.tilt), tilt_ramp=a.ramp, **kw)
        s.neighbours()
        T1 = 2 * np.pi / first_mode(s.depth)
        cols = (np.arange(1, round(s.L / s.dp) - 1) + 0.5) * s.dp
        held = []
        for i in range(1, int(round(a.tend / s.dt)) + 1):
            s.step()
            if blew_up(s):
                print(f"blew up at {s.t:.3f} s")
                break
            if i % 50 == 0:
                speed = np.linalg.norm(s.v, axis=1)
                print(f"t {s.t:.2f} s: mean speed {speed.mean():.2e} m/s, max {speed.max():.2e} m/s")
            if a.tilt != 0 and s.t > a.tend - T1:
                # the surface, more than a spacing from the walls, against the level plane of the tilted tank
                dev = s.height(cols) - (s.depth + np.tan(s.tilt) * (cols - 0.5 * s.L))
                held.append((s.x[:, 0].mean() - 0.5 * s.L, s.x[:, 1].mean(), np.sqrt(np.mean(dev ** 2)),
                             np.abs(dev).max()))
        if held:
            print(level_summary(s, np.array(held), T1))
    else:
        pitch = a.case == 'pitch'
        amp = (np.radians(0.5) if pitch else 0.004) if a.amp is None else a.amp
        w1 = first_mode(a.layers * a.dp)
        w = a.ratio * w1
        motion = dict(pitch_a=amp) if pitch else dict(sway_a=amp)
        s = Sim(a.layers, a.dp, jitter=a.jitter, forcing_w=w, ramp=2 * 2 * np.pi / w, **motion, **kw)
        print(forced_response(s, pitch, a.ratio, a.layers * a.dp))


if __name__ == '__main__':
    main()
