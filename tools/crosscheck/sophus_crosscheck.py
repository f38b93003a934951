#!/usr/bin/env python3
"""Cross-check estimator-core's f64 Lie-group values against Sophus and a 50-digit reference.

Runs `cargo run --release -q -p estimator-core --example lie_dump` (from the workspace root),
reads its JSON lines, and recomputes every quantity with two references that share no code
with estimator-core:

* **Sophus** (C++ Sophus through the `sophuspy` pybind11 wrapper): `exp`, `log`, `matrix`,
  products and inverses. sophuspy exposes no `Adj()` and no Jacobians, so the Sophus adjoint is
  obtained from Sophus alone by conjugation: column i of Ad_a is log(a·exp(e_i)·a⁻¹), which is
  exact (a·exp(x)·a⁻¹ = exp(Ad_a x)) while the rotation part of Ad_a e_i has angle 1 < π.
* **mp** (mpmath, 50 significant digits), built only from the defining series:
  exp = mp.expm(τ^); Ad_{exp τ} = expm(ad_τ); J_r(τ) = Σ_k (−ad_τ)^k/(k+1)!,
  J_l(τ) = Σ_k (ad_τ)^k/(k+1)!, summed until a term is below 1e-45; J⁻¹ = mp.inverse(J);
  log(M) by Newton's method on τ ↦ exp(τ) started from Sophus' f64 log: δ = log(exp(τ)⁻¹ M)
  (a near-identity matrix, log by its Mercator series), τ ← τ + J_r(τ)⁻¹ δ, until ‖δ‖ < 1e-45.
  ad_τ is formed generically from the generators: column j = vee(τ^ G_j − G_j τ^).

Tolerance rule (per case and quantity, max-norm over the entries):
    err = max |ours − ref|,  scale = max(1, max |ref|),  pass iff err ≤ 1e-12 · scale.
The relative difference reported is err / max|ref| (normwise relative).

Verdicts:
* ours vs mp must pass everywhere (mp is exact to far below f64 round-off).
* ours vs Sophus must pass, except where Sophus itself is off: a failure is reported as a
  Sophus-side inaccuracy (not counted) when Sophus vs mp fails the same rule and ours vs mp
  passes. Otherwise it is a real disagreement.
* Logarithms near π: if a log comparison fails and the reference rotation angle is within
  1e-9 of π (where the sign of the axis is ambiguous), the two logs are instead compared through
  Sophus' exp of each (same group element ⇒ pass). No case of the dump is that close; the
  fallback is there so that only a real disagreement is flagged.

Exit status: 0 if no real disagreement, 1 otherwise (2 on a setup error).

Usage (from the workspace root):
    /tmp/xcheck-venv/bin/python tools/crosscheck/sophus_crosscheck.py [--dump FILE] [--verbose]
"""

import argparse
import json
import math
import os
import subprocess
import sys
from collections import defaultdict

import mpmath as mp
import numpy as np
import sophuspy as sp

mp.mp.dps = 50
TOL = 1e-12
PI_AMBIGUITY = 1e-9

# ---------------------------------------------------------------- hat / vee for each group ----


def hat(group, t):
    """τ^ as an mp.matrix, tangent orders: SO2 θ; SE2 [vx, vy, ω]; SO3 ω; SE3 [v; ω]."""
    z = mp.mpf(0)
    if group == "SO2":
        (th,) = t
        return mp.matrix([[z, -th], [th, z]])
    if group == "SE2":
        vx, vy, w = t
        return mp.matrix([[z, -w, vx], [w, z, vy], [z, z, z]])
    if group == "SO3":
        x, y, w3 = t
        return mp.matrix([[z, -w3, y], [w3, z, -x], [-y, x, z]])
    if group == "SE3":
        v1, v2, v3, x, y, w3 = t
        return mp.matrix(
            [[z, -w3, y, v1], [w3, z, -x, v2], [-y, x, z, v3], [z, z, z, z]]
        )
    raise ValueError(group)


def vee(group, m):
    if group == "SO2":
        return [m[1, 0]]
    if group == "SE2":
        return [m[0, 2], m[1, 2], m[1, 0]]
    if group == "SO3":
        return [m[2, 1], m[0, 2], m[1, 0]]
    if group == "SE3":
        return [m[0, 3], m[1, 3], m[2, 3], m[2, 1], m[0, 2], m[1, 0]]
    raise ValueError(group)


DOF = {"SO2": 1, "SE2": 3, "SO3": 3, "SE3": 6}


def generators(group):
    n = DOF[group]
    return [hat(group, [mp.mpf(1) if i == j else mp.mpf(0) for i in range(n)]) for j in range(n)]


GENS = {g: generators(g) for g in DOF}


def ad_matrix(group, t):
    n = DOF[group]
    X = hat(group, t)
    A = mp.zeros(n, n)
    for j, G in enumerate(GENS[group]):
        col = vee(group, X * G - G * X)
        for i in range(n):
            A[i, j] = col[i]
    return A


def phi_series(A, sign):
    """Σ_k (sign·A)^k / (k+1)!  (sign = −1: J_r, +1: J_l)."""
    n = A.rows
    S = mp.eye(n)
    P = mp.eye(n)
    k = 0
    while True:
        k += 1
        P = P * A * (sign / mp.mpf(k + 1))  # (sign A)^k / (k+1)!
        S += P
        if mp.mnorm(P, 1) < mp.mpf("1e-45") and k > 2:
            return S


def mp_vec(xs):
    return [mp.mpf(float(x)) for x in xs]


def mp_mat(m):
    return mp.matrix([[mp.mpf(float(x)) for x in row] for row in m])


def log_near_identity(D):
    """log(D) for D = I + X, ‖X‖ ≪ 1, by the Mercator series."""
    n = D.rows
    X = D - mp.eye(n)
    S = mp.zeros(n, n)
    P = mp.eye(n)
    k = 0
    while True:
        k += 1
        P = P * X
        term = P * (mp.mpf((-1) ** (k + 1)) / k)
        S += term
        if mp.mnorm(term, 1) < mp.mpf("1e-48") or k > 400:
            return S


def mp_log(group, M, start):
    """Principal log of the mp group matrix M, Newton from the f64 `start`."""
    tau = mp_vec(start)
    n = DOF[group]
    for _ in range(12):
        E_inv = mp.expm(-hat(group, tau))
        delta = vee(group, log_near_identity(E_inv * M))
        if max(abs(d) for d in delta) < mp.mpf("1e-45"):
            return tau
        Jr = phi_series(ad_matrix(group, tau), -1)
        step = mp.lu_solve(Jr, mp.matrix(delta))
        tau = [tau[i] + step[i] for i in range(n)]
    raise RuntimeError("Newton log did not converge")


def to_np(x):
    if isinstance(x, mp.matrix):
        return np.array([[float(x[i, j]) for j in range(x.cols)] for i in range(x.rows)])
    return np.array([float(v) for v in x])


# ---------------------------------------------------------------------------- Sophus side ----


def s_exp(group, t):
    t = np.asarray(t, dtype=float)
    if group == "SO2":
        return sp.SO2.exp(float(t[0]))
    cls = {"SE2": sp.SE2, "SO3": sp.SO3, "SE3": sp.SE3}[group]
    return cls.exp(t.reshape(-1))


def s_log(group, g):
    v = g.log()
    return np.atleast_1d(np.asarray(v, dtype=float)).reshape(-1)


def s_adjoint(group, g):
    n = DOF[group]
    ginv = g.inverse()
    A = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1.0
        A[:, j] = s_log(group, g * s_exp(group, e) * ginv)
    return A


def rotation_angle(group, t):
    t = np.asarray(t, dtype=float)
    if group in ("SO2",):
        return abs(t[0])
    if group == "SE2":
        return abs(t[2])
    if group == "SO3":
        return float(np.linalg.norm(t))
    return float(np.linalg.norm(t[3:]))


# ------------------------------------------------------------------------------ comparing ----


def diff(ours, ref):
    ours = np.asarray(ours, dtype=float)
    ref = np.asarray(ref, dtype=float)
    err = float(np.max(np.abs(ours - ref)))
    mag = float(np.max(np.abs(ref)))
    rel = err / mag if mag > 0 else (0.0 if err == 0 else math.inf)
    ok = err <= TOL * max(1.0, mag)
    return err, rel, ok


def compare_log(group, ours, ref):
    err, rel, ok = diff(ours, ref)
    if not ok and rotation_angle(group, ref) > math.pi - PI_AMBIGUITY:
        a = s_exp(group, ours).matrix()
        b = s_exp(group, ref).matrix()
        e2, r2, ok2 = diff(a, b)
        if ok2:
            return e2, r2, True
    return err, rel, ok


def sophus_fd_jacobians(group, tau, h=1e-5):
    """Central differences of Sophus' exp/log: J_r col j = [log(E⁻¹·exp(τ+h e_j)) − (−h)]/2h,
    J_l col j = [log(exp(τ+h e_j)·E⁻¹) − (−h)]/2h. Used only to confirm the conventions
    (sign and side) of the mp series; truncation + round-off is ~1e-10."""
    n = DOF[group]
    tau = np.asarray(tau, dtype=float)
    E_inv = s_exp(group, tau).inverse()
    Jr = np.zeros((n, n))
    Jl = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        p, m = s_exp(group, tau + e), s_exp(group, tau - e)
        Jr[:, j] = (s_log(group, E_inv * p) - s_log(group, E_inv * m)) / (2 * h)
        Jl[:, j] = (s_log(group, p * E_inv) - s_log(group, m * E_inv)) / (2 * h)
    return Jr, Jl


# ---------------------------------------------------------------------------------- main ----


def run_dump(root):
    cmd = ["cargo", "run", "--release", "-q", "-p", "estimator-core", "--example", "lie_dump"]
    res = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
    if res.returncode != 0:
        sys.stderr.write(res.stderr)
        sys.exit(2)
    return res.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dump", help="read JSON lines from this file instead of running cargo")
    ap.add_argument("--verbose", action="store_true", help="print every failing comparison")
    args = ap.parse_args()

    root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
    text = open(args.dump).read() if args.dump else run_dump(root)
    records = [json.loads(line) for line in text.splitlines() if line.strip()]

    # stats[(group, quantity, class)][ref] = [max_err, max_rel, n, n_fail]
    stats = defaultdict(lambda: defaultdict(lambda: [0.0, 0.0, 0, 0]))
    sophus_side = []
    real = []
    fd_max = defaultdict(float)  # (group, class) -> max |mp series − Sophus finite difference|

    def record(key, refname, res):
        s = stats[key][refname]
        s[0] = max(s[0], res[0])
        s[1] = max(s[1], res[1])
        s[2] += 1
        s[3] += 0 if res[2] else 1

    for r in records:
        g, cls, kind = r["group"], r["class"], r["kind"]
        items = []  # (quantity, ours, sophus_ref or None, mp_ref, is_log)
        if kind == "single":
            tau = r["tau"]
            t_mp = mp_vec(tau)
            X = hat(g, t_mp)
            E = mp.expm(X)
            A = ad_matrix(g, t_mp)
            Jr = phi_series(A, -1)
            Jl = phi_series(A, +1)
            sg = s_exp(g, tau)
            s_log_v = s_log(g, sg)
            # Not on the tiny class: Sophus' own SE(2)/SE(3) exp loses up to ~1e-8 there (see
            # the Sophus−mp column), which a difference quotient amplifies by 1/h.
            if cls != "tiny":
                fr, fl = sophus_fd_jacobians(g, tau)
                fd_max[(g, cls)] = max(fd_max[(g, cls)], float(np.max(np.abs(fr - to_np(Jr)))),
                                       float(np.max(np.abs(fl - to_np(Jl)))))
            items += [
                ("exp", r["exp"], sg.matrix(), to_np(E), False),
                ("log", r["log"], s_log_v, to_np(mp_log(g, E, s_log_v)), True),
                ("adj", r["adj"], s_adjoint(g, sg), to_np(mp.expm(A)), False),
                ("jr", r["jr"], None, to_np(Jr), False),
                ("jl", r["jl"], None, to_np(Jl), False),
                ("jr_inv", r["jr_inv"], None, to_np(mp.inverse(Jr)), False),
                ("jl_inv", r["jl_inv"], None, to_np(mp.inverse(Jl)), False),
            ]
            inp = {"tau": tau}
        else:
            ta, tb = r["tau_a"], r["tau_b"]
            Ea = mp.expm(hat(g, mp_vec(ta)))
            Eb = mp.expm(hat(g, mp_vec(tb)))
            a, b = s_exp(g, ta), s_exp(g, tb)
            s_bl = s_log(g, a.inverse() * b)
            Bm = mp.inverse(Ea) * Eb
            items += [
                ("compose", r["compose"], (a * b).matrix(), to_np(Ea * Eb), False),
                ("between_log", r["between_log"], s_bl, to_np(mp_log(g, Bm, s_bl)), True),
            ]
            inp = {"tau_a": ta, "tau_b": tb}

        for q, ours, s_ref, m_ref, is_log in items:
            key = (g, q, cls)
            cmp = (lambda o, f: compare_log(g, o, f)) if is_log else diff
            om = cmp(ours, m_ref)
            record(key, "ours-mp", om)
            if s_ref is not None:
                osr = cmp(ours, s_ref)
                smr = cmp(s_ref, m_ref)
                record(key, "ours-sophus", osr)
                record(key, "sophus-mp", smr)
                if not osr[2]:
                    entry = dict(group=g, cls=cls, id=r["id"], quantity=q, **inp,
                                 ours=np.asarray(ours).tolist(),
                                 sophus=np.asarray(s_ref).tolist(),
                                 mp=np.asarray(m_ref).tolist(),
                                 err_ours_sophus=osr[0], err_ours_mp=om[0],
                                 err_sophus_mp=smr[0])
                    if om[2] and not smr[2]:
                        sophus_side.append(entry)
                    else:
                        real.append(entry)
            if not om[2] and not any(
                e["group"] == g and e["id"] == r["id"] and e["quantity"] == q for e in real
            ):
                real.append(dict(group=g, cls=cls, id=r["id"], quantity=q, **inp,
                                 ours=np.asarray(ours).tolist(),
                                 mp=np.asarray(m_ref).tolist(), err_ours_mp=om[0]))

    # ---- report ----
    print(f"{len(records)} records; tolerance: max|d| <= {TOL:g} * max(1, max|ref|)\n")
    order_g = ["SO3", "SE3", "SO2", "SE2"]
    order_q = ["exp", "log", "adj", "jr", "jl", "jr_inv", "jl_inv", "compose", "between_log"]
    order_c = ["random", "tiny", "near_pi"]

    def fmt(s):
        if s is None:
            return "—", "—"
        return f"{s[0]:.1e}", f"{s[1]:.1e}"

    print("| group | quantity | class | n | ours−Sophus abs | rel | ours−mp abs | rel "
          "| Sophus−mp abs | fails (ours−Sophus / ours−mp) |")
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---|")
    for g in order_g:
        for q in order_q:
            for c in order_c:
                key = (g, q, c)
                if key not in stats:
                    continue
                st = stats[key]
                os_, om_, sm_ = st.get("ours-sophus"), st.get("ours-mp"), st.get("sophus-mp")
                a1, r1 = fmt(os_)
                a2, r2 = fmt(om_)
                a3, _ = fmt(sm_)
                f1 = os_[3] if os_ else "—"
                print(f"| {g} | {q} | {c} | {om_[2]} | {a1} | {r1} | {a2} | {r2} | {a3} "
                      f"| {f1} / {om_[3]} |")

    # Summary: max over groups per quantity and class.
    print("\nSummary (max over the four groups):\n")
    print("| quantity | class | ours−Sophus abs | rel | ours−mp abs | rel | Sophus−mp abs |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for q in order_q:
        for c in order_c:
            agg = {}
            for ref in ("ours-sophus", "ours-mp", "sophus-mp"):
                vals = [stats[(g, q, c)][ref] for g in order_g
                        if (g, q, c) in stats and ref in stats[(g, q, c)]]
                agg[ref] = (max(v[0] for v in vals), max(v[1] for v in vals)) if vals else None
            a1, r1 = fmt(agg["ours-sophus"])
            a2, r2 = fmt(agg["ours-mp"])
            a3, _ = fmt(agg["sophus-mp"])
            print(f"| {q} | {c} | {a1} | {r1} | {a2} | {r2} | {a3} |")

    print("\nReference self-check (conventions of the mp Jacobian series): max |series − "
          "central difference of Sophus exp/log, h = 1e-5| per group/class: "
          + ", ".join(f"{g}/{c} {v:.1e}" for (g, c), v in sorted(fd_max.items())))
    fd_bad = [k for k, v in fd_max.items() if v > 1e-7]
    if fd_bad:
        print(f"REFERENCE SELF-CHECK FAILED for {fd_bad}: the mp Jacobians do not match Sophus")
        return 2

    if sophus_side:
        print(f"\n{len(sophus_side)} ours−Sophus differences above tolerance are Sophus-side "
              "(Sophus vs mp fails, ours vs mp passes):")
        for e in sophus_side:
            tau = e.get("tau", (e.get("tau_a"), e.get("tau_b")))
            print(f"  {e['group']} {e['quantity']} {e['cls']} id={e['id']} input={tau} "
                  f"|ours−Sophus|={e['err_ours_sophus']:.2e} |ours−mp|={e['err_ours_mp']:.2e} "
                  f"|Sophus−mp|={e['err_sophus_mp']:.2e}")
    if real:
        print(f"\nREAL DISAGREEMENTS: {len(real)}")
        for e in real:
            print(json.dumps(e))
        return 1
    print("\nNo real disagreement.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
