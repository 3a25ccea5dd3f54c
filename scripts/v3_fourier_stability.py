#!/usr/bin/python3
"""Fourier (von Neumann) analysis of the V3 step in 1D on a periodic lattice.

The nodes sit at integer positions (dx = 1), the stress points halfway between them; the
cubic B-spline with h = 1.2 dx; rho = 1, constrained modulus M = 1 (so c_d = 1 and dt = C),
S_w = 1. Every corrected operator of the scheme is then a multiplier per wave number k, and one
step maps (v, sigma', p_w) at the nodes linearly: a 3 x 3 amplification matrix A(k). A storage
form is stable when the spectral radius of A(k) is at most 1 for every k.

The forms (docs/method-notes.md §2.4):
  nodes_inc       "nodes" with the incremental projection, eq. (2.4.10) (the former default)
  nodes           "nodes", non-incremental, eq. (2.4.8)
  sp              "stress_points", non-incremental, eq. (2.4.14)
  sp_inc          "stress_points" with the incremental term of the node operator D G (the
                  combination the reader rejects)
  consistent      eq. (2.4.20): nodes_inc plus S_w (D v^n - D_N v^{n+1/2}) (the default)

Usage: v3_fourier_stability.py [Q/M ...]   (default 10 and 66: K_f = 0.1 GPa in Case 13's
soil and water's 2.2 GPa in Case 16's). Prints the largest |eigenvalue| over k for C = 0.2,
0.5, 0.8 and, for C = 0.5, the moduli of the three eigenvalues at a few k.
"""
import sys

import numpy as np

H = 1.2
NODES = np.array([j for j in range(-4, 5) if j != 0], float)
HALF = np.array([j + 0.5 for j in range(-4, 4)], float)


def kernel(r):
    q = np.abs(r) / H
    return np.where(q < 1, 2 / 3 - q * q + 0.5 * q**3, np.where(q < 2, (2 - q) ** 3 / 6, 0.0))


def kernel_slope(r):
    q = np.abs(r) / H
    return np.where(q < 1, -2 * q + 1.5 * q * q, np.where(q < 2, -0.5 * (2 - q) ** 2, 0.0)) / H


def symbols(k):
    """Multipliers of: node gradient G (= node divergence D), the node Laplacian L, the
    interpolation nodes -> stress points P and the cross-set gradient Gs (both directions)."""
    slope = kernel_slope(NODES) * np.sign(NODES)
    g = np.sum(np.exp(1j * k * NODES) * slope) / np.sum(NODES * slope)
    f = -kernel_slope(NODES) / np.abs(NODES)
    lap = 2 * np.sum((np.cos(k * NODES) - 1) * f) / np.sum(NODES**2 * f)
    p = np.sum(kernel(HALF) * np.exp(1j * k * HALF)) / np.sum(kernel(HALF))
    slope_h = kernel_slope(HALF) * np.sign(HALF)
    gs = np.sum(np.exp(1j * k * HALF) * slope_h) / np.sum(HALF * slope_h)
    return g, lap, p, gs


def amplification(k, courant, q_over_m, form):
    dt = courant
    g, lap, p_int, gs = symbols(k)
    a = np.zeros((3, 3), complex)
    for col in range(3):
        v, s, p = np.eye(3)[col].astype(complex)
        v_free = p_int * v + 0.5 * dt * gs * s  # the stress points' pressure-free half step
        v_half = v_free - 0.5 * dt * gs * p  # eq. (2.4.1)
        s_half = p_int * s + 0.5 * dt * gs * v
        v_star = v + dt * gs * s_half  # eq. (2.4.3)
        s_new = s + dt * gs * v_half  # eq. (2.4.4)
        iq = 1.0 / (q_over_m * dt)
        if form in ("nodes", "nodes_inc", "consistent"):
            c = dt
            rhs = iq * p - g * v_star
            if form != "nodes":
                rhs += c * g * g * p - c * lap * p  # incremental: eq. (2.4.10)
            if form == "consistent":
                rhs += g * v - gs * v_half  # eq. (2.4.20)
        else:
            c = 0.5 * dt
            rhs = iq * p - gs * v_free
            if form == "sp_inc":
                rhs += c * g * g * p - c * lap * p
        p_new = rhs / (iq - c * lap)
        v_new = v_star - dt * g * p_new  # eq. (2.4.9)
        a[:, col] = [v_new, s_new, p_new]
    return a


def main():
    ratios = [float(x) for x in sys.argv[1:]] or [10.0, 66.0]
    forms = ["nodes_inc", "nodes", "sp", "sp_inc", "consistent"]
    ks = np.linspace(0.01, np.pi, 400)
    for q in ratios:
        for form in forms:
            for courant in (0.2, 0.5, 0.8):
                radius = [max(abs(np.linalg.eigvals(amplification(k, courant, q, form)))) for k in ks]
                i = int(np.argmax(radius))
                print(f"Q*/M = {q:g}  {form:10s}  C = {courant}: max |lambda| = {radius[i]:.6f} at k dx = {ks[i]:.3f}")
        print(f"Q*/M = {q:g}, C = 0.5: |lambda| of the three modes at k dx = 0.5, 1.5, 2.5, pi")
        for form in forms:
            row = []
            for k in (0.5, 1.5, 2.5, np.pi):
                ev = sorted(abs(np.linalg.eigvals(amplification(k, 0.5, q, form))))
                row.append(" ".join(f"{e:.4f}" for e in ev))
            print(f"  {form:10s}  " + "  |  ".join(row))


if __name__ == "__main__":
    main()
