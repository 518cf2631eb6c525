"""The time loop of the vectorised joint loads (``design_rules.vectorised._Group.joint_loads``), compiled.

The arithmetic is the numpy code's, sample for sample and design for design (see the docstring of
``design_rules.vectorised``): link kinematics in closed form, added mass and drag as moments of the strips
(prefix sums, cut where the section's normal velocity changes sign), the caudal fin's lift and added mass, and the
suffix sums over the links. What changes is only where the work is done: numpy made some thirty temporaries of
(samples, designs) per link and sample block; here each sample, link and design is one pass of scalar arithmetic
with the designs innermost, which the compiler vectorises. The findings agree with ``swiftfin check`` to rounding
(tests/test_vectorised_rules.py, relative 1e-9); the benchmark is ``bench/bench_rules.py``.

Compiled by numba on first use and cached beside this file (or in numba's user cache when that folder is read-only).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(inline="always")
def _max(cur, x):
    """np.maximum of two floats: NaN wins, as in numpy (a design with a NaN goes to the per-design code)."""
    return x if (x > cur or x != x) else cur


@njit(inline="always")
def _min(cur, x):
    """np.minimum of two floats, NaN winning."""
    return x if (x < cur or x != x) else cur



@njit(cache=True, nogil=True, error_model="numpy")
def time_loop(C_all, S_all, om, U, a, b, sa, sb, nodes, dxn, tot, w_first, w_last, lo, hi, cum, e0, step,
              masses, a_c, b_c, x_c, izz, aq, bq, saq, sbq, xq, rho, area, a_slope, cd90, cmax, m_af, x_root,
              tau, thetad, thetadd, amp_ratio, den_bad, root_peak):
    """Fill ``tau``, ``thetad``, ``thetadd`` (n, T, N): joint torque, rate and acceleration on the samples
    (C_all, S_all) = (cos w t, sin w t); ``amp_ratio`` (n, N): the largest |num| / den of the joints' relative
    angle atan2(num, den) over the samples, and ``den_bad`` (n, N) where den <= 0 at some sample (the caller
    takes atan2 sample by sample there). Returns the largest |chord slope| of each design (N,).

    Shapes: a, b (n+2, N) wave coefficients at the nodes; sa, sb, dxn (n+1, N) per link; tot (n, 7, N) the
    strip moments of each link; cum (strips+1, 7, N) their prefix sums; lo, hi (n, N) each link's strips; the
    fin's (2, N) quarter-chord and centroid coefficients (aq, bq, saq, sbq, xq). ``root_peak`` (N,): the largest
    |moment| of the fin's two forces about the station ``x_root`` (N,) on the last link (its socket's mouth)."""
    n = tau.shape[0]
    T = C_all.shape[0]
    N = a.shape[1]
    smax = np.zeros(N)
    e1 = np.empty((n, N))
    e2 = np.empty((n, N))
    e3 = np.empty((n, N))
    yj = np.empty((n, N))
    p_sig = np.empty(N)
    p_phid = np.empty(N)
    p_phidd = np.empty(N)
    for t in range(T):
        C = C_all[t]
        S = S_all[t]
        for d in range(N):
            w = om[d]
            w2 = w * w
            sig = sa[0, d] * C + sb[0, d] * S
            sigd = w * sb[0, d] * C - w * sa[0, d] * S
            c2 = 1.0 / (1.0 + sig * sig)
            phid = sigd * c2
            p_sig[d] = sig
            p_phid[d] = phid
            p_phidd[d] = -c2 * sig * (w2 + 2.0 * sigd * phid)
            smax[d] = _max(smax[d], abs(sig))
        for k in range(1, n + 1):
            j = k - 1
            for d in range(N):
                w = om[d]
                w2 = w * w
                sig = sa[k, d] * C + sb[k, d] * S
                sigd = w * sb[k, d] * C - w * sa[k, d] * S
                c2 = 1.0 / (1.0 + sig * sig)
                cph = math.sqrt(c2)
                sph = sig * cph
                phid = sigd * c2
                phidd = -c2 * sig * (w2 + 2.0 * sigd * phid)
                smax[d] = _max(smax[d], abs(sig))
                thetad[j, t, d] = phid - p_phid[d]
                thetadd[j, t, d] = phidd - p_phidd[d]
                num = sig - p_sig[d]
                den = 1.0 + sig * p_sig[d]
                if den > 0.0:
                    amp_ratio[j, d] = max(amp_ratio[j, d], abs(num) / den)
                else:
                    den_bad[j, d] = True
                p_sig[d] = sig
                p_phid[d] = phid
                p_phidd[d] = phidd
                yk = a[k, d] * C + b[k, d] * S
                yj[j, d] = yk
                vk = w * b[k, d] * C - w * a[k, d] * S
                dy = sig * dxn[k, d]
                dv = sigd * dxn[k, d]
                P = U[d] * sph + cph * vk
                Q = cph * dv
                spd = sph * phid
                Pd = cph * (U[d] * phid - w2 * yk) - spd * vk
                Qd = -w2 * (cph * dy) - spd * dv
                H0 = Pd * tot[j, 0, d] + Qd * tot[j, 1, d]
                H1 = Pd * tot[j, 1, d] + Qd * tot[j, 2, d]
                PP = P * P
                PQ = 2.0 * P * Q
                QQ = Q * Q
                G0 = PP * tot[j, 3, d] + PQ * tot[j, 4, d] + QQ * tot[j, 5, d]
                G1 = PP * tot[j, 4, d] + PQ * tot[j, 5, d] + QQ * tot[j, 6, d]
                W0 = P + Q * w_first[j, d]
                W1 = P + Q * w_last[j, d]
                if (W0 < 0.0) != (W1 < 0.0):
                    # w changes sign on the link: the strips below its zero count negative
                    q = math.ceil((nodes[k, d] - e0[d] + (-P / Q) * dxn[k, d]) / step[d] - 0.5)
                    q = min(max(q, lo[j, d]), hi[j, d])
                    qi = int(q)
                    l0 = cum[qi, 3, d] - cum[lo[j, d], 3, d]
                    l1 = cum[qi, 4, d] - cum[lo[j, d], 4, d]
                    l2 = cum[qi, 5, d] - cum[lo[j, d], 5, d]
                    l3 = cum[qi, 6, d] - cum[lo[j, d], 6, d]
                    sq = 1.0 if Q > 0.0 else (-1.0 if Q < 0.0 else 0.0)
                    G0 = sq * (G0 - 2.0 * (PP * l0 + PQ * l1 + QQ * l2))
                    G1 = sq * (G1 - 2.0 * (PP * l1 + PQ * l2 + QQ * l3))
                else:
                    s = W0 + W1
                    sgn = 1.0 if s > 0.0 else (-1.0 if s < 0.0 else 0.0)
                    G0 *= sgn
                    G1 *= sgn
                H0 += G0
                H1 += G1
                E = -w2 * masses[j, d] * (a_c[j, d] * C + b_c[j, d] * S)
                e1[j, d] = ((cph * nodes[k, d] + sph * yk) * H0 + (cph * dxn[k, d] + sph * dy) * H1
                            + E * x_c[j, d] + izz[j, d] * phidd)
                e2[j, d] = cph * H0 + E
                e3[j, d] = sph * H0
        # suffix sums over the links, the moment about each joint, then the caudal fin
        for k in range(n - 2, -1, -1):
            for d in range(N):
                e1[k, d] += e1[k + 1, d]
                e2[k, d] += e2[k + 1, d]
                e3[k, d] += e3[k + 1, d]
        for j in range(n):
            for d in range(N):
                tau[j, t, d] = e1[j, d] - nodes[j + 1, d] * e2[j, d] - yj[j, d] * e3[j, d]
        for d in range(N):
            w = om[d]
            w2 = w * w
            sig_q = saq[0, d] * C + sbq[0, d] * S
            sig_c = saq[1, d] * C + sbq[1, d] * S
            smax[d] = _max(_max(smax[d], abs(sig_q)), abs(sig_c))
            c_q = math.sqrt(1.0 / (1.0 + sig_q * sig_q))
            s_q = sig_q * c_q
            c2c = 1.0 / (1.0 + sig_c * sig_c)
            c_c = math.sqrt(c2c)
            s_c = sig_c * c_c
            pd_c = (w * sbq[1, d] * C - w * saq[1, d] * S) * c2c
            vf = w * bq[0, d] * C - w * aq[0, d] * S
            wf = U[d] * s_q + vf * c_q
            uf = U[d] * c_q - vf * s_q
            V2 = uf * uf + wf * wf
            cn = (a_slope[d] * wf * uf + cd90[d] * wf * abs(wf)) / V2 if V2 > 0.0 else 0.0
            cn = min(max(cn, -cmax[d]), cmax[d])
            f_lift = 0.5 * rho[d] * area[d] * V2 * cn
            yc = aq[1, d] * C + bq[1, d] * S
            vc = w * bq[1, d] * C - w * aq[1, d] * S
            f_fam = m_af[d] * (U[d] * c_c * pd_c - vc * s_c * pd_c - w2 * yc * c_c)
            # the socket's mouth: on the last link, between the last joint (node n) and the tail end (node n + 1)
            wr = (x_root[d] - nodes[n, d]) / (nodes[n + 1, d] - nodes[n, d])
            y_root = yj[n - 1, d] * (1.0 - wr) + (a[n + 1, d] * C + b[n + 1, d] * S) * wr
            m_root = 0.0
            for p in range(2):
                force = f_lift if p == 0 else f_fam
                fc = force * (c_q if p == 0 else c_c)
                fs = force * (s_q if p == 0 else s_c)
                yq = aq[p, d] * C + bq[p, d] * S
                for j in range(n):
                    lever = xq[p, d] - nodes[j + 1, d]
                    if lever > 0.0:
                        tau[j, t, d] += fc * lever + fs * (yq - yj[j, d])
                if xq[p, d] > x_root[d]:
                    m_root += fc * (xq[p, d] - x_root[d]) + fs * (yq - y_root)
            root_peak[d] = _max(root_peak[d], abs(m_root))
    return smax


@njit(cache=True, nogil=True, error_model="numpy")
def strip_moments(e0, e_end, n_strips, nodes, H, L_mm, t_naca, c_am, c_dr, cum, lo, hi, w_first, w_last):
    """The body strips from joint 1 to the hull end and the moments the loads need: added mass
    alpha {1, u, u^2} and drag beta {1, u, u^2, u^3} of each strip (u along its link), summed from the first strip
    into ``cum`` (strips+1, 7, N); ``lo``, ``hi`` (n, N) the strips of link k (1..n) and ``w_first``, ``w_last``
    (n, N) their first and last u. The same operations as the numpy code this replaced: the strips' edges are
    ``np.linspace(e0, e_end, strips + 1)``, the height is ``2 H naca_half_width`` (``layout.geometry``), a strip
    belongs to the link whose nodes bracket its middle."""
    N = nodes.shape[1]
    n = lo.shape[0]
    MM = 1e-3
    ks = np.empty((n_strips, N), np.int64)
    ws = np.empty((n_strips, N))
    for d in range(N):
        for q in range(7):
            cum[0, q, d] = 0.0
    for i in range(n_strips):
        for d in range(N):
            step = (e_end[d] - e0[d]) / n_strips
            x0 = i * step + e0[d]
            x1 = e_end[d] if i + 1 == n_strips else (i + 1) * step + e0[d]
            x = 0.5 * (x1 + x0)
            dx = x1 - x0
            xi = min(max(x / MM / L_mm[d], 0.0), 1.0)
            half = 5.0 * t_naca[d] * (0.2969 * math.sqrt(xi)
                                       + xi * (-0.1260 + xi * (-0.3516 + xi * (0.2843 - 0.1015 * xi)))) * L_mm[d]
            h = 2.0 * (H[d] * half) * MM
            k = -1
            for q in range(n + 2):
                if x >= nodes[q, d]:
                    k += 1
            k = min(max(k, 0), n)
            u = (x - nodes[k, d]) / (nodes[k + 1, d] - nodes[k, d])
            ks[i, d] = k
            ws[i, d] = u
            m = c_am[d] * ((h / 2) * (h / 2)) * dx
            cum[i + 1, 0, d] = cum[i, 0, d] + m
            m *= u
            cum[i + 1, 1, d] = cum[i, 1, d] + m
            m *= u
            cum[i + 1, 2, d] = cum[i, 2, d] + m
            m = c_dr[d] * h * dx
            cum[i + 1, 3, d] = cum[i, 3, d] + m
            for q in range(4, 7):
                m *= u
                cum[i + 1, q, d] = cum[i, q, d] + m
    for d in range(N):
        for k in range(1, n + 1):
            below = 0
            upto = 0
            for i in range(n_strips):
                below += ks[i, d] < k
                upto += ks[i, d] <= k
            lo[k - 1, d] = below
            hi[k - 1, d] = upto
            w_first[k - 1, d] = ws[min(below, n_strips - 1), d]
            w_last[k - 1, d] = ws[min(max(upto - 1, 0), n_strips - 1), d]


@njit(cache=True, nogil=True, error_model="numpy")
def drive(m, r, T0, EA, mu, Jm, ratio_w, inv_step, bend, length, tau, rate, acc,
          need, steps, peak_motor, peak_tension, peak_spool, comp_max, cap_min):
    """Cable tensions, motor torque and step rate of each joint over the half period (``layout.loads.drive_loads``
    and what the rules read of it): fills ``need`` (n, T, N), the motor torque over both halves (the second half
    period is the first with torque, rate and acceleration negated), ``steps`` the full-step rate, and the (n, N)
    peaks: motor torque, cable tension, spool tension, cable compliance angle; ``cap_min`` the least capstan
    capacity (holding side over pulling side). ``bend``, ``length`` (2, n, N): the left and right cables'
    wrap angle in the guides and free length. The numpy code's operations, sample by sample."""
    n, T, N = tau.shape
    ul = np.empty(N)
    ur = np.empty(N)
    el = np.empty(N)
    er = np.empty(N)
    il = np.empty(N)
    ir = np.empty(N)
    ckl = np.empty(N)
    ckr = np.empty(N)
    for j in range(n):
        for d in range(N):
            peak_motor[j, d] = -np.inf
            peak_tension[j, d] = -np.inf
            peak_spool[j, d] = -np.inf
            comp_max[j, d] = -np.inf
            cap_min[j, d] = np.inf
            kl = EA[d] / length[0, j, d]
            kr = EA[d] / length[1, j, d]
            km = (kl + kr) * m[d]
            ul[d] = kl / km
            ur[d] = kr / km
            el[d] = math.exp(mu[d] * bend[0, j, d])
            er[d] = math.exp(mu[d] * bend[1, j, d])
            il[d] = 1.0 / el[d]
            ir[d] = 1.0 / er[d]
            ckl[d] = 1.0 / (kl * m[d])
            ckr[d] = 1.0 / (kr * m[d])
        for t in range(T):
            for d in range(N):
                tq = tau[j, t, d]
                rt = rate[j, t, d]
                vl = tq * ul[d]
                vr = tq * ur[d]
                nd = 0.0
                for h in range(2):
                    half = 1.0 if h == 0 else -1.0
                    if h == 0:
                        ta = T0[d] + vl
                        tb = T0[d] - vr
                    else:
                        ta = T0[d] - vl
                        tb = T0[d] + vr
                    if tb < 0.0:
                        ta = half * tq / m[d]
                        tb = 0.0
                    if ta < 0.0:
                        tb = -half * tq / m[d]
                        ta = 0.0
                    toward = rt >= 0.0 if h == 0 else rt <= 0.0
                    sl = ta * (el[d] if toward else il[d])
                    sr = tb * (ir[d] if toward else er[d])
                    tt = _max(sl, sr)
                    ts = _min(sl, sr)
                    tm = abs((sl - sr) * r[d] + (half * Jm[d]) * acc[j, t, d])
                    nd = tm if h == 0 else _max(nd, tm)
                    left = ta >= tb
                    tmax = ta if left else tb
                    peak_tension[j, d] = _max(peak_tension[j, d], tmax)
                    comp_max[j, d] = _max(comp_max[j, d], (tmax - T0[d]) * (ckl[d] if left else ckr[d]))
                    peak_spool[j, d] = _max(peak_spool[j, d], tt)
                    cap_min[j, d] = _min(cap_min[j, d], ts * ratio_w[d] / max(tt, 1e-12))
                peak_motor[j, d] = _max(peak_motor[j, d], nd)
                need[j, t, d] = nd
                steps[j, t, d] = abs(rt) * inv_step[d]


@njit(cache=True, nogil=True, error_model="numpy")
def pullout_ratio(rates, torques, steps, need, ratio_min, max_rate):
    """Least ratio of the pull-out torque available at each sample's full-step rate to the torque it needs
    (``physics.stepper_pullout``: the curve read linearly between its points, flat beyond its ends), over the
    samples of every joint: ``steps``, ``need`` (K, N) -> ``ratio_min`` (N,), and ``max_rate`` (N,) the
    highest step rate. ``rates``, ``torques`` (W, N): each design's curve, padded with NaN."""
    W, N = rates.shape
    K = steps.shape[0]
    n_pts = np.zeros(N, np.int64)
    for d in range(N):
        for p in range(W):
            if not math.isnan(rates[p, d]):
                n_pts[d] += 1
        ratio_min[d] = np.inf
        max_rate[d] = -np.inf
    for k in range(K):
        for d in range(N):
            x = steps[k, d]
            max_rate[d] = _max(max_rate[d], x)
            i = 0
            for p in range(1, n_pts[d]):
                if x >= rates[p, d]:
                    i += 1
            if i >= n_pts[d] - 1:
                avail = torques[n_pts[d] - 1, d]
            elif x < rates[0, d]:
                avail = torques[0, d]
            else:
                slope = (torques[i + 1, d] - torques[i, d]) / (rates[i + 1, d] - rates[i, d])
                avail = slope * (x - rates[i, d]) + torques[i, d]
            nd = need[k, d]
            ratio_min[d] = _min(ratio_min[d], avail / max(nd, 1e-12) if nd > 0.0 else np.inf)
