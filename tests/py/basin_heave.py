"""Linear potential-flow heave of the floating box of sph/tests/bodies.rs in its closed basin (2D).

The box (beam B = 0.2 m, draught T = 0.15 m, mass rho B T per metre) floats in the middle of a basin L = 0.8 m
long filled D = 0.25 m deep. The radiation potential of unit heave velocity solves Laplace's equation in the
water (finite volumes, cell size h): no flux through the basin's walls and floor and the box's sides, the box's
bottom moving up at 1, and the linear free-surface condition phi_z = (omega^2 / g) phi on the open surface. The
added mass A33(omega) = rho * integral of phi over the box's bottom then holds the inertia of the water and the
basin's level rise (-rho g B^2 / (L - B) / omega^2), so the heave period solves omega^2 (m + A33(omega)) = rho g B.
Prints A33 and the period for h = 5 and 2.5 mm. Needs numpy and scipy; not run by the tests (their reference
value is the period printed here).
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sl

RHO, G = 1000.0, 9.81
L, D, B, T = 0.8, 0.25, 0.2, 0.15


def added_mass(omega, h):
    nx, nz = int(round(L / h)), int(round(D / h))
    xc = -L / 2 + (np.arange(nx) + 0.5) * h
    zc = (np.arange(nz) + 0.5) * h
    zb = D - T
    idx = -np.ones((nx, nz), int)
    n = 0
    for i in range(nx):
        for k in range(nz):
            if not (abs(xc[i]) < B / 2 and zc[k] > zb):
                idx[i, k] = n
                n += 1
    k_s = omega**2 / G / (1 - omega**2 / G * h / 2)  # phi_z = k_s * phi at the cell centre below the surface
    rows, cols, vals = [], [], []
    rhs = np.zeros(n)
    for i in range(nx):
        for k in range(nz):
            p = idx[i, k]
            if p < 0:
                continue
            diag = 0.0
            for di, dk in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                ii, kk = i + di, k + dk
                if ii < 0 or ii >= nx or kk < 0:
                    continue  # the basin's walls and floor
                if kk >= nz:
                    diag += k_s * h  # flux through the free surface
                    continue
                q = idx[ii, kk]
                if q < 0:
                    if dk == 1:
                        rhs[p] -= h  # the box's bottom, moving up at 1
                    continue  # the box's sides
                rows.append(p)
                cols.append(q)
                vals.append(1.0)
                diag -= 1.0
            rows.append(p)
            cols.append(p)
            vals.append(diag)
    phi = sl.spsolve(sp.csc_matrix((vals, (rows, cols)), shape=(n, n)), rhs)
    kb = int(round(zb / h)) - 1
    return RHO * sum((phi[idx[i, kb]] + 0.5 * h) * h for i in range(nx) if abs(xc[i]) < B / 2)


if __name__ == "__main__":
    m = RHO * B * T
    for h in (0.005, 0.0025):
        period = 0.85
        for _ in range(100):
            omega = 2 * np.pi / period
            a33 = added_mass(omega, h)
            new = 2 * np.pi * np.sqrt((m + a33) / (RHO * G * B))
            if abs(new - period) < 1e-7:
                break
            period = 0.5 * (period + new)
        print(f"h {h}: heave period {period:.4f} s, A33(omega) {a33:.2f} kg/m, high frequency {added_mass(1e4, h):.2f} kg/m")
