"""An independent planar frame-element ring (numpy), to check the closed-form Fourier compliance of wgcad.elastic.ring."""

import numpy as np


def fe_ring(r, EI, n_el, loads, ea_factor=1e6):
    """Straight Euler-Bernoulli frame elements on a regular n_el-gon inscribed in radius r.

    loads: list of (node, radial N, tangential N, couple N mm). Rigid-body modes removed by
    three Lagrange constraints (sum of ux, of uy, of rotation moments), which is the gauge of the
    Fourier solution (no n = 0, 1 terms). Returns w, v, theta at the nodes.
    """
    EA = ea_factor * EI / r**2
    ang = 2 * np.pi * np.arange(n_el) / n_el
    X = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    ndof = 3 * n_el
    K = np.zeros((ndof, ndof))
    for e in range(n_el):
        i, j = e, (e + 1) % n_el
        d = X[j] - X[i]
        L = np.hypot(*d)
        c, s = d / L
        k = np.zeros((6, 6))
        a, b1, b2, b3 = EA / L, 12 * EI / L**3, 6 * EI / L**2, EI / L
        k[np.ix_([0, 3], [0, 3])] = a * np.array([[1, -1], [-1, 1]])
        idx = [1, 2, 4, 5]
        k[np.ix_(idx, idx)] = np.array(
            [[b1, b2, -b1, b2], [b2, 4 * b3, -b2, 2 * b3], [-b1, -b2, b1, -b2], [b2, 2 * b3, -b2, 4 * b3]]
        )
        T = np.zeros((6, 6))
        R = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
        T[:3, :3] = R
        T[3:, 3:] = R
        kg = T.T @ k @ T
        dofs = [3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2]
        K[np.ix_(dofs, dofs)] += kg
    f = np.zeros(ndof)
    for node, pr, pt, cm in loads:
        er = np.array([np.cos(ang[node]), np.sin(ang[node])])
        et = np.array([-er[1], er[0]])
        f[3 * node : 3 * node + 2] += pr * er + pt * et
        f[3 * node + 2] += cm
    C = np.zeros((ndof, 3))
    C[0::3, 0] = 1.0
    C[1::3, 1] = 1.0
    C[0::3, 2] = -X[:, 1]
    C[1::3, 2] = X[:, 0]
    C[2::3, 2] = 1.0
    A = np.block([[K, C], [C.T, np.zeros((3, 3))]])
    u = np.linalg.solve(A, np.concatenate([f, np.zeros(3)]))[:ndof]
    ux, uy, rz = u[0::3], u[1::3], u[2::3]
    w = ux * np.cos(ang) + uy * np.sin(ang)
    v = -ux * np.sin(ang) + uy * np.cos(ang)
    return ang, w, v, rz
