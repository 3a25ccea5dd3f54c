#!/usr/bin/python3
"""Williams corner eigenvalue of a plane-strain elastic wedge (Case 4(a) toe).

What it solves.  A wedge 0 <= theta <= alpha (polar coordinates at the apex), one edge
traction-free (sigma_tt = sigma_rt = 0 on theta = 0) and the other clamped (u_r = u_t = 0 on
theta = alpha), homogeneous isotropic, plane strain (kappa = 3 - 4 nu).  Separable fields
    phi = r^(lam+1) F(theta),  F = A cos(lam+1)t + B sin(lam+1)t + C cos(lam-1)t + D sin(lam-1)t
give stresses ~ r^(lam-1) and displacements ~ r^lam.  The four edge conditions are a 4x4
linear system in (A, B, C, D); lam is an eigenvalue where its determinant vanishes.  The
smallest root with Re lam > 0 governs the corner: stresses ~ r^(Re lam - 1), singular when
Re lam < 1.  For Case 4(a) the toe is the corner of the block where the rough (clamped) base
y = 0 meets the free face x = W: alpha = pi/2, nu = 0.3.

Stresses from phi (Airy):  s_rr = r^(lam-1) [(lam+1) F + F''],  s_tt = r^(lam-1) lam (lam+1) F,
s_rt = -r^(lam-1) lam F'.  Displacements (Barber, Elasticity, Table 8.1, for this basis):
  2 mu u_r = r^lam [-(lam+1)(A c1 + B s1) + (kappa - lam)(C c2 + D s2)]
  2 mu u_t = r^lam [ (lam+1)(A s1 - B c1) + (kappa + lam)(C s2 - D c2)]
with c1 = cos(lam+1)t, s1 = sin(lam+1)t, c2 = cos(lam-1)t, s2 = sin(lam-1)t.  The script does not
take that table on trust: `check_displacements` differentiates these displacements numerically
and checks that the strains equal plane-strain Hooke's law applied to the Airy stresses.

Verification against known results (all run by `main`):
  * free-free wedge (Williams 1952): roots of sin(lam alpha) = +- lam sin(alpha); alpha = 2 pi
    (crack) gives lam = 1/2; alpha = 3 pi / 2 (re-entrant right angle) gives lam = 0.5445.
  * clamped-clamped wedge: kappa sin(lam alpha) = +- lam sin(alpha).
  * clamped-free, alpha = pi: the crack on a rigid interface (Williams 1959, England 1965;
    the rigid limit of the bimaterial oscillation index): lam = 1/2 + i ln(kappa) / (2 pi).
  * the determinant of the clamped-free case has the same roots as the closed form
        kappa^2 + 1 + 2 kappa cos(2 lam alpha) - 4 lam^2 sin^2(alpha) = 0
    (checked here at several angles; at alpha = pi it reduces to the rigid-interface crack).

Usage: /usr/bin/python3 scripts/williams_corner.py [nu]    (default nu = 0.3)
"""
import sys

import numpy as np


def basis(lam, t):
    a, b = lam + 1.0, lam - 1.0
    return np.cos(a * t), np.sin(a * t), np.cos(b * t), np.sin(b * t)


def rows_free(lam, t):
    """F(t) and F'(t) as rows over (A, B, C, D): sigma_tt = sigma_rt = 0 (lam != 0, -1)."""
    c1, s1, c2, s2 = basis(lam, t)
    a, b = lam + 1.0, lam - 1.0
    return [np.array([c1, s1, c2, s2]), np.array([-a * s1, a * c1, -b * s2, b * c2])]


def rows_clamped(lam, t, kappa):
    """2 mu u_r / r^lam and 2 mu u_t / r^lam as rows over (A, B, C, D)."""
    c1, s1, c2, s2 = basis(lam, t)
    a = lam + 1.0
    ur = np.array([-a * c1, -a * s1, (kappa - lam) * c2, (kappa - lam) * s2])
    ut = np.array([a * s1, -a * c1, (kappa + lam) * s2, -(kappa + lam) * c2])
    return [ur, ut]


def det(lam, alpha, kappa, kind):
    """Determinant of the edge conditions; kind = 'free-clamped', 'free-free', 'clamped-clamped'."""
    lam = complex(lam)
    e0, e1 = kind.split("-")
    rows = []
    for edge, t in ((e0, 0.0), (e1, alpha)):
        rows += rows_free(lam, t) if edge == "free" else rows_clamped(lam, t, kappa)
    return np.linalg.det(np.array(rows, dtype=complex))


def newton(f, z0, tol=1e-13, maxit=100):
    z = complex(z0)
    for _ in range(maxit):
        h = 1e-7 * max(1.0, abs(z))
        d = (f(z + h) - f(z - h)) / (2 * h)
        if d == 0:
            return None
        dz = f(z) / d
        z -= dz
        if abs(dz) < tol * max(1.0, abs(z)):
            return z
    return None


def roots(f, re_max=3.0, im_max=1.0):
    """Roots with 0 < Re lam <= re_max found by Newton from a grid of starts, deduplicated."""
    found = []
    for x0 in np.linspace(0.05, re_max, 40):
        for y0 in np.linspace(0.0, im_max, 6):
            z = newton(f, complex(x0, y0))
            if z is None or not (1e-6 < z.real <= re_max) or abs(f(z)) > 1e-8:
                continue
            z = complex(z.real, abs(z.imag))  # roots come in conjugate pairs
            if abs(z.imag) < 1e-9:
                z = complex(z.real, 0.0)
            if all(abs(z - w) > 1e-7 for w in found):
                found.append(z)
    return sorted(found, key=lambda z: (z.real, z.imag))


def airy_fields(lam, coef, kappa, mu, r, t):
    """Stresses and displacements (real lam, real coefficients) at (r, t)."""
    A, B, C, D = coef
    c1, s1, c2, s2 = basis(lam, t)
    a, b = lam + 1.0, lam - 1.0
    F = A * c1 + B * s1 + C * c2 + D * s2
    Fp = -a * A * s1 + a * B * c1 - b * C * s2 + b * D * c2
    Fpp = -a * a * (A * c1 + B * s1) - b * b * (C * c2 + D * s2)
    srr = r ** (lam - 1) * (a * F + Fpp)
    stt = r ** (lam - 1) * lam * a * F
    srt = -(r ** (lam - 1)) * lam * Fp
    ur = r**lam * (-a * (A * c1 + B * s1) + (kappa - lam) * (C * c2 + D * s2)) / (2 * mu)
    ut = r**lam * (a * (A * s1 - B * c1) + (kappa + lam) * (C * s2 - D * c2)) / (2 * mu)
    return srr, stt, srt, ur, ut


def check_displacements(nu):
    """Strains of the displacement formulas = plane-strain Hooke of the Airy stresses."""
    kappa, mu = 3 - 4 * nu, 1.0
    rng = np.random.default_rng(1)
    worst = 0.0
    for lam in (0.37, 0.711, 1.6, 2.3):
        coef = rng.normal(size=4)
        for r, t in ((0.7, 0.3), (1.3, 1.1), (2.0, 2.5)):
            h = 1e-5
            f = lambda rr, tt: airy_fields(lam, coef, kappa, mu, rr, tt)
            srr, stt, srt, ur, ut = f(r, t)
            dur_dr = (f(r + h, t)[3] - f(r - h, t)[3]) / (2 * h)
            dur_dt = (f(r, t + h)[3] - f(r, t - h)[3]) / (2 * h)
            dut_dr = (f(r + h, t)[4] - f(r - h, t)[4]) / (2 * h)
            dut_dt = (f(r, t + h)[4] - f(r, t - h)[4]) / (2 * h)
            err = ur / r + dut_dt / r
            ert = 0.5 * (dur_dt / r + dut_dr - ut / r)
            tr = srr + stt
            hooke = (srr - nu * tr, stt - nu * tr, srt)  # 2 mu * strain, plane strain
            got = (2 * mu * dur_dr, 2 * mu * err, 2 * mu * ert)
            scale = max(abs(srr), abs(stt), abs(srt), 1.0)
            worst = max(worst, max(abs(g - e) for g, e in zip(got, hooke)) / scale)
    return worst


def toe_mode_extrapolation(lam, kappa, rows=5):
    """The pure corner mode of the Case 4(a) toe, measured as validate 04 measures the face:
    stress-point values at (W - dx/2, y) and (W - 3 dx/2, y), y = (k - 1/2) dx, extrapolated
    linearly to x = W.  The exact field is traction-free there; what the extrapolation leaves
    is the measure's own error on a field that varies as r^(lam - 1) within a cell.  Returned
    per row k relative to the mode's sigma_yy on the face at the same y (scale-free: it is the
    same for every dx, so this part of the residual also grows as dx^(lam - 1))."""
    M = np.array(rows_free(lam, 0.0) + rows_clamped(lam, np.pi / 2, kappa))
    coef = np.linalg.svd(M)[2][-1].real

    def sig(X, Y):  # X = x - W <= 0, Y = y; theta = 0 along the face (0, 1), pi/2 along the base
        r, th = np.hypot(Y, -X), np.arctan2(-X, Y)
        srr, stt, srt, _, _ = airy_fields(lam, coef, kappa, 1.0, r, th)
        c, s = np.cos(th + np.pi / 2), np.sin(th + np.pi / 2)
        return (srr * c * c + stt * s * s - 2 * srt * s * c, srr * s * s + stt * c * c + 2 * srt * s * c,
                (srr - stt) * s * c + srt * (c * c - s * s))

    out = []
    for k in range(1, rows + 1):
        y = k - 0.5
        a, b, f = sig(-0.5, y), sig(-1.5, y), sig(0.0, y)
        assert abs(f[0]) < 1e-9 * abs(f[1]) and abs(f[2]) < 1e-9 * abs(f[1])  # the face is free
        out.append((k, (a[0] + 0.5 * (a[0] - b[0])) / f[1], (a[2] + 0.5 * (a[2] - b[2])) / f[1]))
    return out


def main():
    nu = float(sys.argv[1]) if len(sys.argv) > 1 else 0.3
    kappa = 3 - 4 * nu
    ok = True

    def report(label, got, want, tol=1e-6):
        nonlocal ok
        good = abs(got - want) < tol
        ok &= good
        print(f"  {label}: {got:.6f}  (expected {want:.6f})  {'ok' if good else 'MISMATCH'}")

    print(f"nu = {nu}, kappa = 3 - 4 nu = {kappa}")
    e = check_displacements(nu)
    print(f"displacement formulas vs plane-strain Hooke (finite differences): max rel. error {e:.1e}")
    ok &= e < 1e-6

    print("checks against known results:")
    r = roots(lambda z: det(z, 2 * np.pi, kappa, "free-free"))
    report("free-free, alpha = 2 pi (crack), lowest lam", r[0].real, 0.5)
    r = roots(lambda z: det(z, 1.5 * np.pi, kappa, "free-free"))
    report("free-free, alpha = 3 pi/2, lowest lam (Williams 1952: 0.5445)", r[0].real, 0.544484, 1e-5)
    for al in (0.75 * np.pi, 1.5 * np.pi):
        r = roots(lambda z: det(z, al, kappa, "clamped-clamped"))
        g = lambda z: kappa * np.sin(z * al) - z * np.sin(al)
        h = lambda z: kappa * np.sin(z * al) + z * np.sin(al)
        ref = sorted([z for z in roots(g) + roots(h) if abs(z.imag) < 1e-9], key=lambda z: z.real)
        ref_r = [z for z in r if abs(z.imag) < 1e-9]
        report(f"clamped-clamped, alpha = {al / np.pi:.2f} pi, lowest real lam vs kappa sin(lam a) = +-lam sin a",
               ref_r[0].real, ref[0].real)
    r = roots(lambda z: det(z, np.pi, kappa, "free-clamped"))
    z = r[0]
    report("free-clamped, alpha = pi (rigid-interface crack), Re lam", z.real, 0.5)
    report("free-clamped, alpha = pi, Im lam = ln(kappa)/(2 pi)", z.imag, np.log(kappa) / (2 * np.pi))
    for al in (np.pi / 4, np.pi / 2, 0.8 * np.pi, 1.5 * np.pi):
        closed = lambda z: kappa**2 + 1 + 2 * kappa * np.cos(2 * z * al) - 4 * z**2 * np.sin(al) ** 2
        a_ = roots(lambda z: det(z, al, kappa, "free-clamped"))[0]
        b_ = roots(closed)[0]
        report(f"free-clamped, alpha = {al / np.pi:.2f} pi: determinant root vs closed form (|diff|)",
               abs(a_ - b_), 0.0, 1e-7)

    print("\nCase 4(a) toe: alpha = pi/2, base clamped, face free, plane strain")
    r = roots(lambda z: det(z, np.pi / 2, kappa, "free-clamped"))
    for z in r[:4]:
        print(f"  lam = {z.real:.6f}{'' if z.imag == 0 else f' + {z.imag:.6f} i'}   stress ~ r^{z.real - 1:+.6f}")
    lam = r[0].real
    print(f"\nlowest: lam = {lam:.6f}, stress exponent lam - 1 = {lam - 1:.6f}")
    print("row k of a lattice of spacing dx sits at r ~ (k - 1/2) dx from the toe: a fixed-row residual")
    print(f"grows as dx^(lam-1): x {2 ** (1 - lam):.4f} per halving of dx;")
    print(f"the face RMS (L2 over the face) falls as dx^(lam-1/2) = dx^{lam - 0.5:.4f}: x {2 ** (0.5 - lam):.4f} per halving")
    print("\nthe pure corner mode measured like validate 04 (linear extrapolation of the stress points")
    print("to the face); residual / the mode's face sigma_yy at the same height, per row k from the toe:")
    for k, sn, st in toe_mode_extrapolation(lam, kappa):
        print(f"  k = {k}: s_n {sn:+.4f}, s_t {st:+.4f}")
    if not ok:
        print("SOME CHECKS FAILED")
        sys.exit(1)


if __name__ == "__main__":
    main()
