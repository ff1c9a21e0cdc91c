"""The contact modes in closed form: whether a law has it, and each mode's modal
decomposition (made once per law and scenario, :func:`~.entries.set_up_modes`).

With a linear law (loading ``F = k z + c zd``, unloading ``F = k' z + c' zd``: terms ``z`` and
``zd`` only) and nothing else acting during the contact (no cubic support, mass loss, permanent set
or impact-scaled terms), the loading and the unloading modes are linear systems ``y' = M y + b_c +
b_s sin(w t)`` (``b_c`` gravity, ``b_s`` the drive on the frame).  With ``M = V diag(lambda) V^-1``
the modal coordinates ``q = V^-1 y`` decouple: ``q_j' = lambda_j q_j + beta_cj + beta_sj sin(w t)``,
and ``q_j = u_j + q_sj(t)`` with the periodic part ``q_sj = (A_j e^(iwt) - A'_j e^(-iwt)) / 2i``
(``A_j = beta_sj / (iw - lambda_j)``, ``A'_j = beta_sj / (-iw - lambda_j)``) and ``u_j(s) =
e^(lambda_j s) u_j(0) + beta_cj s phi1(lambda_j s)`` (``phi1(x) = (e^x - 1) / x``: a zero
eigenvalue, a frame with ``k1 = 0``, needs no special case).  The decomposition is made once per run
and mode (:func:`_contact_eig`: the eigenvalues are the roots of the two-mass system's quartic
``det(lambda^2 Mass + lambda C + K)``, whose coefficients have no cancellation, the eigenvectors its
2x2 null vectors; no LAPACK call, a few microseconds), and checked in the state scaled by the
absolute tolerances; a mode whose eigenpairs miss their residual, whose scaled eigenvectors are
ill-conditioned (condition above ``_CONTACT_COND``: near a defective, critically damped pair, or a
free frame ``k1 = c1 = 0``) or with an eigenvalue within ``1e-9 w`` of the drive's ``+-iw`` (an
undamped resonance) is integrated instead.
"""

import numpy as np
from numba import njit

from .codes import LOAD, P_CONTACT, P_K3, P_LOSS, P_SET, P_VSCALE, borrowed_njit

_CONTACT_COND = 1e5  # the largest condition number of a mode's scaled eigenvectors
NE = 12  # a mode's complex constants per eigenvalue, :func:`_contact_setup`
NR = 6  # a mode's real constants, :func:`_contact_setup`


@borrowed_njit
def _contact_law(law, kc):
    """Whether the contact has the closed form: requested (``p[P_CONTACT] = 1``), a linear
    law and nothing else acting during the contact (see the module); fills ``kc`` with the
    loading force's ``(k, c)``, then the unloading force's."""
    p, coef, ea, eb, br = law
    if p[P_CONTACT] == 0.0 or p[P_K3] != 0.0 or p[P_LOSS] != 0.0:
        return False
    if p[P_SET] != 0.0 or p[P_VSCALE] != 0.0:
        return False
    if not (p[0] > 0.0 and p[1] > 0.0 and p[5] > 0.0):
        return False
    for j in range(4):
        kc[j] = 0.0
    for i in range(coef.shape[0]):
        if ea[i] == 1.0 and eb[i] == 0.0:
            if br[i] == 0.0:
                kc[0] += coef[i]  # the elastic part acts in both branches
            kc[2] += coef[i]
        elif ea[i] == 0.0 and eb[i] == 1.0:
            kc[1 if br[i] == 0.0 else 3] += coef[i]
        else:
            return False
    for j in range(4):
        if not np.isfinite(kc[j]):
            return False
    return True


@njit(cache=True, inline="always")
def _contact_g(mode, kc, i):
    """Switching function ``i`` of a contact mode as ``(gz, gv)``: ``h = gz z + gv zd``
    (loss, unload or reload, release: as :func:`_switching`)."""
    if i == 0:
        return 1.0, 0.0
    if i == 1:
        return 0.0, (1.0 if mode == LOAD else -1.0)
    if mode == LOAD:
        return kc[0], kc[1]
    return kc[2], kc[3]


@njit(cache=True)
def _cinv4(A, out):
    """``out = A^-1`` of a complex 4x4 by Gauss-Jordan with partial pivoting; False if a
    pivot vanishes (singular to working precision)."""
    W = A.copy()
    for r in range(4):
        for c in range(4):
            out[r, c] = 1.0 if r == c else 0.0
    for c in range(4):
        piv, big = c, abs(W[c, c])
        for r in range(c + 1, 4):
            if abs(W[r, c]) > big:
                piv, big = r, abs(W[r, c])
        if not big > 1e-300:
            return False
        for k in range(4):
            W[c, k], W[piv, k] = W[piv, k], W[c, k]
            out[c, k], out[piv, k] = out[piv, k], out[c, k]
        d = W[c, c]
        for k in range(4):
            W[c, k] /= d
            out[c, k] /= d
        for r in range(4):
            if r != c:
                m = W[r, c]
                for k in range(4):
                    W[r, k] -= m * W[c, k]
                    out[r, k] -= m * out[c, k]
    return True


@njit(cache=True)
def _contact_matrix(p, k, c, dsc, Ms):
    """``Ms = D^-1 M D``: the contact mode's system matrix (force ``k z + c zd``) in the state
    scaled by ``D = diag(dsc)``; False if not finite."""
    m1, m2, k1, c1 = p[0], p[1], p[2], p[3]
    M = np.zeros((4, 4))
    M[0, 1] = 1.0
    M[1, 0], M[1, 1], M[1, 2], M[1, 3] = -(k1 + k) / m1, -(c1 + c) / m1, k / m1, c / m1
    M[2, 3] = 1.0
    M[3, 0], M[3, 1], M[3, 2], M[3, 3] = k / m2, c / m2, -k / m2, -c / m2
    for r in range(4):
        for q in range(4):
            if not np.isfinite(M[r, q]):
                return False
            Ms[r, q] = M[r, q] * dsc[q] / dsc[r]
    return True


@njit(cache=True)
def _quartic_roots(a3, a2, a1, a0, z):
    """The roots of ``x^4 + a3 x^3 + a2 x^2 + a1 x + a0`` into ``z`` (complex, 4): the
    Aberth-Ehrlich iteration on the polynomial scaled to roots of order 1 at most (the caller
    checks the eigenpairs they give)."""
    r = max(abs(a3), np.sqrt(abs(a2)), abs(a1) ** (1.0 / 3.0), np.sqrt(np.sqrt(abs(a0))))
    if not r > 0.0:
        for k in range(4):
            z[k] = 0.0
        return
    b3, b2, b1, b0 = a3 / r, a2 / r**2, a1 / r**3, a0 / r**4
    # the starts: the roots' sizes as the coefficients' ratios suggest (exact for widely
    # separated roots), at spread angles
    z[0] = abs(b3)
    z[1] = abs(b2 / b3) if b3 != 0.0 else 1.0
    z[2] = abs(b1 / b2) if b2 != 0.0 else 1.0
    z[3] = abs(b0 / b1) if b1 != 0.0 else 1e-3
    for k in range(4):
        rad = min(max(z[k].real, 1e-8), 2.0)
        z[k] = rad * np.exp(1j * (0.4 + 1.6 * k))
    last = np.inf
    for _ in range(100):
        big = 0.0
        for k in range(4):
            x = z[k]
            f = (((x + b3) * x + b2) * x + b1) * x + b0
            df = ((4.0 * x + 3.0 * b3) * x + 2.0 * b2) * x + b1
            if f == 0.0:
                continue
            s = 0j
            for j in range(4):
                if j != k:
                    s += 1.0 / (x - z[j])
            ratio = f / df if df != 0.0 else f
            step = ratio / (1.0 - ratio * s)
            z[k] = x - step
            big = max(big, abs(step) / max(abs(z[k]), 1e-12))
        # converged: the steps at rounding level, or no longer shrinking once small
        if big < 4e-16 or (big < 1e-9 and big >= 0.5 * last):
            break
        last = big
    for k in range(4):
        z[k] *= r


@njit(cache=True)
def _contact_eig(p, k, c, lam, V):
    """The eigenvalues ``lam`` and eigenvectors ``V`` (columns, in the state's order) of a
    contact mode's system (force ``k z + c zd``): the roots of ``det(lambda^2 Mass + lambda C +
    K)``, whose coefficients are sums of non-negative terms for non-negative parameters
    (``k1 k / (m1 m2)``, ...: no cancellation), and each root's null vector ``x`` of that
    2x2 matrix, ``v = (x1, lambda x1, x2, lambda x2)``."""
    m1, m2, k1, c1 = p[0], p[1], p[2], p[3]
    a3 = (c1 + c) / m1 + c / m2
    a2 = (k1 + k) / m1 + k / m2 + c1 * c / (m1 * m2)
    a1 = (c1 * k + c * k1) / (m1 * m2)
    a0 = k1 * k / (m1 * m2)
    _quartic_roots(a3, a2, a1, a0, lam)
    for j in range(4):
        la = lam[j]
        q11 = la * la + la * (c1 + c) / m1 + (k1 + k) / m1
        q12 = -(la * c + k) / m1
        q21 = -(la * c + k) / m2
        q22 = la * la + la * c / m2 + k / m2
        if abs(q11) + abs(q12) >= abs(q21) + abs(q22):
            x1, x2 = -q12, q11
        else:
            x1, x2 = q22, -q21
        V[0, j], V[1, j], V[2, j], V[3, j] = x1, la * x1, x2, la * x2


@njit(cache=True)
def _contact_eig_scaled(p, k, c, dsc, Ms, lam, Vs):
    """The eigen-decomposition of ``Ms`` (:func:`_contact_matrix`) by :func:`_contact_eig`,
    its eigenvectors scaled by ``D^-1`` and normalised; False if a pair misses ``Ms v = lambda
    v`` by more than 1e-12 of ``|Ms|``."""
    _contact_eig(p, k, c, lam, Vs)
    nm = 0.0
    for r in range(4):
        for q in range(4):
            nm += abs(Ms[r, q]) ** 2
    nm = np.sqrt(nm)
    for j in range(4):
        n = 0.0
        for r in range(4):
            Vs[r, j] /= dsc[r]
            n += abs(Vs[r, j]) ** 2
        n = np.sqrt(n)
        if not n > 0.0:
            return False
        for r in range(4):
            Vs[r, j] /= n
        res = 0.0
        for r in range(4):
            acc = -lam[j] * Vs[r, j]
            for q in range(4):
                acc += Ms[r, q] * Vs[q, j]
            res += abs(acc) ** 2
        if not np.sqrt(res) <= 1e-12 * nm:
            return False
    return True


@njit(cache=True)
def _contact_setup(p, kc, mode, dsc, E, R):
    """The closed form's constants of a contact mode (``mi = 0`` loading, 1 unloading): for
    each eigenvalue ``j``, ``E[mi, j]`` holds its eigenvector ``v_j`` (4), the row ``j`` of
    ``V^-1`` (4), ``lambda_j``, ``beta_cj``, ``A_j``, ``A'_j``; ``R[mi]`` holds 1 where the
    mode has the closed form (else 0 and nothing else), the periodic parts' curvature bound
    of its three switching functions, the largest ``Re lambda`` and the smallest
    ``|lambda|``."""
    mi = 0 if mode == LOAD else 1
    R[mi, 0] = 0.0
    w, g = p[5], p[6]
    Ms = np.empty((4, 4), dtype=np.complex128)
    if not _contact_matrix(p, kc[2 * mi], kc[2 * mi + 1], dsc, Ms):
        return
    lam = np.empty(4, dtype=np.complex128)
    Vs = np.empty((4, 4), dtype=np.complex128)
    if not _contact_eig_scaled(p, kc[2 * mi], kc[2 * mi + 1], dsc, Ms, lam, Vs):
        return
    Vis = np.empty((4, 4), dtype=np.complex128)
    if not _cinv4(Vs, Vis):
        return
    n1, n2 = 0.0, 0.0
    for r in range(4):
        for q in range(4):
            n1 += abs(Vs[r, q]) ** 2
            n2 += abs(Vis[r, q]) ** 2
    if not np.sqrt(n1 * n2) <= _CONTACT_COND:
        return
    grow = -np.inf
    for j in range(4):
        la = lam[j]
        dp, dm = 1j * w - la, -1j * w - la
        if not (abs(dp) > 1e-9 * w and abs(dm) > 1e-9 * w):
            return
        for r in range(4):
            E[mi, j, r] = Vs[r, j] * dsc[r]
            E[mi, j, 4 + r] = Vis[j, r] / dsc[r]
        beta_s = -E[mi, j, 5] * p[4] / p[0]  # the drive -A sin(w t) / m1 on v1
        E[mi, j, 8] = la
        E[mi, j, 9] = -g * (E[mi, j, 5] + E[mi, j, 7])  # gravity on v1 and v2
        E[mi, j, 10] = beta_s / dp
        E[mi, j, 11] = beta_s / dm
        grow = max(grow, la.real)
    for i in range(3):
        gz, gv = _contact_g(mode, kc, i)
        kf = 0.0
        for j in range(4):
            G = gz * (E[mi, j, 0] - E[mi, j, 2]) + gv * (E[mi, j, 1] - E[mi, j, 3])
            kf += abs(G) * (abs(E[mi, j, 10]) + abs(E[mi, j, 11]))
        R[mi, 1 + i] = 0.5 * w * w * kf
    R[mi, 4] = grow
    R[mi, 5] = min(abs(lam[0]), abs(lam[1]), abs(lam[2]), abs(lam[3]))
    R[mi, 0] = 1.0
