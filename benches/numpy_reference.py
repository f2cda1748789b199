#!/usr/bin/env python3
"""A numpy implementation of spherecal's pipeline with the paper's method,
for the speed comparison in README ("Speed"): read a FORMAT.md session,
fit every stripe (Taubin start, Gauss-Newton orthogonal fit, 4-sigma MAD
trimming), sphere centres by eq. 21, the initial hand-eye by eq. 6-9, the
paper's identification (eq. 10-19: disjoint pairs, column-scaled truncated
SVD) iterated until eps <= threshold, the validation statistics, and the
result JSON. Vectorised where numpy can (forward kinematics and Jacobians
of all measurements at once).

    python3 benches/numpy_reference.py SESSION.json RESULT.json

It checks nothing FORMAT.md asks of a loader: it is a speed reference, not
a tool.
"""
import json
import sys

import numpy as np

ANGLE_SCALE = 1000.0


def fit_circle(p):
    """Taubin's algebraic fit, Gauss-Newton on |p - c| - r, MAD trimming."""
    keep = np.ones(len(p), bool)
    for _ in range(8):
        q = p[keep]
        m = q.mean(0)
        x, y = (q - m).T
        z = x * x + y * y
        zm = z.mean()
        z0 = (z - zm) / (2 * np.sqrt(zm))
        a = np.column_stack([z0, x, y])
        _, _, vt = np.linalg.svd(a, full_matrices=False)
        v = vt[2]
        v0 = v[0] / (2 * np.sqrt(zm))
        v3 = -zm * v0
        c = -v[1:] / (2 * v0)
        r = np.sqrt(c @ c - v3 / v0)
        c = c + m
        for _ in range(10):
            d = q - c
            dist = np.hypot(d[:, 0], d[:, 1])
            res = dist - r
            j = np.column_stack([-d[:, 0] / dist, -d[:, 1] / dist, -np.ones(len(q))])
            step, *_ = np.linalg.lstsq(j, -res, rcond=None)
            c = c + step[:2]
            r = r + step[2]
            if np.abs(step).max() < 1e-12:
                break
        all_res = np.hypot(*(p - c).T) - r
        if len(p) < 20:
            break
        med = np.median(all_res)
        mad = 1.4826 * np.median(np.abs(all_res - med))
        new = np.abs(all_res - med) <= max(4 * mad, 1e-9 * r)
        if (new == keep).all():
            break
        keep = new
    return c, r


def rx(a):
    c, s = np.cos(a), np.sin(a)
    t = np.zeros(a.shape + (4, 4))
    t[..., 0, 0] = 1
    t[..., 1, 1], t[..., 1, 2], t[..., 2, 1], t[..., 2, 2] = c, -s, s, c
    t[..., 3, 3] = 1
    return t


def ry(a):
    c, s = np.cos(a), np.sin(a)
    t = np.zeros(a.shape + (4, 4))
    t[..., 1, 1] = 1
    t[..., 0, 0], t[..., 0, 2], t[..., 2, 0], t[..., 2, 2] = c, s, -s, c
    t[..., 3, 3] = 1
    return t


def rz(a):
    c, s = np.cos(a), np.sin(a)
    t = np.zeros(a.shape + (4, 4))
    t[..., 2, 2] = 1
    t[..., 0, 0], t[..., 0, 1], t[..., 1, 0], t[..., 1, 1] = c, -s, s, c
    t[..., 3, 3] = 1
    return t


def tr(x, y, z):
    t = np.broadcast_to(np.eye(4), np.broadcast(x, y, z).shape + (4, 4)).copy()
    t[..., 0, 3], t[..., 1, 3], t[..., 2, 3] = x, y, z
    return t


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def links(params, q):
    """Link transforms (M, n, 4, 4) and their five parameter derivatives."""
    al, a, be, th, d = (params[:, k] for k in range(5))
    z = np.zeros_like(q)
    A = rx(al + z)
    T = tr(a + z, z, z)
    B = ry(be + z)
    C = rz(q + th)
    D = tr(z, z, d + z)
    dA = A.copy()
    dA[..., 1:3, 1:3] = A[..., 1:3, 1:3] @ np.array([[0, -1], [1, 0]])
    dA[..., 0, 0] = dA[..., 3, 3] = 0
    dB = np.zeros_like(B)
    dB[..., 0, 0], dB[..., 0, 2] = -B[..., 0, 2], B[..., 0, 0]
    dB[..., 2, 0], dB[..., 2, 2] = -B[..., 0, 0], -B[..., 0, 2]
    dC = np.zeros_like(C)
    dC[..., 0, 0], dC[..., 0, 1] = -C[..., 1, 0], -C[..., 0, 0]
    dC[..., 1, 0], dC[..., 1, 1] = C[..., 0, 0], -C[..., 1, 0]
    dT = np.zeros_like(T)
    dT[..., 0, 3] = 1
    dD = np.zeros_like(D)
    dD[..., 2, 3] = 1
    L = A @ T @ B @ C @ D
    dL = [dA @ T @ B @ C @ D, A @ dT @ B @ C @ D, A @ T @ dB @ C @ D,
          A @ T @ B @ dC @ D, A @ T @ B @ C @ dD]
    return L, dL


def fk_jac(robot, joints):
    """Flange poses (M, 4, 4) and d(pose)/d(param) (M, 5n, 4, 4)."""
    params = np.array([[j["alpha"], j["a"], j["beta"], j["theta"], j["d"]] for j in robot["joints"]])
    params[:, [0, 2, 3]] = np.radians(params[:, [0, 2, 3]])
    q = np.radians(joints)
    m, n = q.shape
    Ls, dLs = [], []
    for i in range(n):
        L, dL = links(np.repeat(params[i:i + 1], m, 0), q[:, i])
        Ls.append(L)
        dLs.append(dL)
    pre = [np.broadcast_to(robot["base"], (m, 4, 4))]
    for L in Ls:
        pre.append(pre[-1] @ L)
    post = [np.broadcast_to(robot["flange"], (m, 4, 4))]
    for L in reversed(Ls):
        post.append(L @ post[-1])
    post = post[::-1]
    jac = np.stack([pre[i] @ dLs[i][k] @ post[i + 1] for i in range(n) for k in range(5)], 1)
    return pre[-1], jac


def centres_in_base(pose, he, c):
    t = pose @ he
    return np.einsum("mij,mj->mi", t[:, :3, :3], c) + t[:, :3, 3]


def epsilon(x, groups):
    ss, n = 0.0, 0
    for idx in groups:
        d = x[idx][:, None, :] - x[idx][None, :, :]
        ss += (d ** 2).sum() / 2
        n += len(idx) * (len(idx) - 1) // 2
    return np.sqrt(ss / max(n - 1, 1))


def exp_twist(tw):
    w = tw[3:]
    th = np.linalg.norm(w)
    k = skew(w)
    r = np.eye(3) + (np.sin(th) / th if th > 0 else 1) * k + ((1 - np.cos(th)) / th ** 2 if th > 0 else 0.5) * k @ k
    t = np.eye(4)
    t[:3, :3] = r
    t[:3, 3] = tw[:3]
    return t


def main(session_path, result_path):
    s = json.load(open(session_path))
    robot = s["robot"]
    robot["base"] = np.array(robot.get("base", np.eye(4)), float)
    robot["flange"] = np.array(robot.get("flange", np.eye(4)), float)
    big_r = s["sphere"]["diameter"] / 2
    side0 = s.get("sensor", {}).get("side", 1)
    ms = s["measurements"]
    joints = np.array([m["joints"] for m in ms], float)
    sensor = np.zeros((len(ms), 3))
    for i, m in enumerate(ms):
        if "centre" in m:
            sensor[i] = m["centre"]
            continue
        (yc, zc), r = fit_circle(np.array(m["stripe"]["points"], float))
        t = np.sqrt(max(big_r ** 2 - r ** 2, 0))
        sensor[i] = [m.get("side", side0) * t, yc, zc]
    use = np.array([m["use"] for m in ms])
    pose, _ = fk_jac(robot, joints)
    # Eq. 6-7: rotation from the translations (Procrustes), eq. 8-9:
    # translation from the rotations (least squares).
    ti = np.where(use == "translation")[0]
    r0 = pose[ti[0], :3, :3]
    dc = sensor[ti[1:]] - sensor[ti[0]]
    dp = -(pose[ti[1:], :3, 3] - pose[ti[0], :3, 3]) @ r0
    u, _, vt = np.linalg.svd(dp.T @ dc)
    rhe = u @ np.diag([1, 1, np.linalg.det(u @ vt)]) @ vt
    ri = np.where(use == "rotation")[0]
    rows, rhs = [], []
    for a in range(len(ri)):
        for b in range(a + 1, len(ri)):
            i, j = ri[a], ri[b]
            rows.append(pose[i, :3, :3] - pose[j, :3, :3])
            rhs.append(pose[j, :3, :3] @ rhe @ sensor[j] + pose[j, :3, 3]
                       - pose[i, :3, :3] @ rhe @ sensor[i] - pose[i, :3, 3])
    the = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    he = np.eye(4)
    he[:3, :3], he[:3, 3] = rhe, the
    he0 = he.copy()
    stations = {}
    for i, m in enumerate(ms):
        if m["use"] == "identify":
            stations.setdefault(m["station"], []).append(i)
    groups = [np.array(v) for v in stations.values()]
    ident = np.concatenate(groups)
    nominal = json.loads(json.dumps(robot, default=lambda o: o.tolist()))
    cur = dict(robot)
    cur["joints"] = [dict(j) for j in robot["joints"]]
    nparam = 5 * len(cur["joints"])
    scale = np.array([1, 1, 1] + [ANGLE_SCALE] * 3 + [ANGLE_SCALE, 1, ANGLE_SCALE, ANGLE_SCALE, 1] * (nparam // 5))
    threshold = s.get("solver", {}).get("threshold", 0.15)
    max_it = s.get("solver", {}).get("max_iterations", 20)
    before = centres_in_base(pose, he, sensor)
    pose, jac = fk_jac(cur, joints[ident])
    eps = [epsilon(centres_in_base(pose, he, sensor[ident]), [np.arange(len(g)) + o for g, o in zip(groups, np.cumsum([0] + [len(g) for g in groups[:-1]]))])]
    local = [np.arange(len(g)) + o for g, o in zip(groups, np.cumsum([0] + [len(g) for g in groups[:-1]]))]
    while eps[-1] > threshold and len(eps) - 1 < max_it:
        xs = sensor[ident]
        bs = pose @ he
        xb = np.einsum("mij,mj->mi", bs[:, :3, :3], xs) + bs[:, :3, 3]
        a = np.zeros((len(ident), 3, 6 + nparam))
        for k in range(len(ident)):
            rbs = bs[k, :3, :3]
            a[k, :, :3] = rbs
            a[k, :, 3:6] = -rbs @ skew(xs[k])
            q = np.hstack([np.eye(3), -skew(xb[k])])
            rot = pose[k, :3, :3]
            for p in range(nparam):
                dt = jac[k, p]
                # Twist of the flange in the base frame for parameter p.
                w = dt[:3, :3] @ rot.T
                tw = np.concatenate([dt[:3, 3] - w @ pose[k, :3, 3], [w[2, 1], w[0, 2], w[1, 0]]])
                a[k, :, 6 + p] = q @ tw
        blocks, v = [], []
        for g in local:
            for i, j in zip(g[0::2], g[1::2]):
                blocks.append(a[j] - a[i])
                v.append(xb[i] - xb[j])
        u_m = np.vstack(blocks) / scale
        uu, sv, vt = np.linalg.svd(u_m, full_matrices=False)
        keep = sv >= 1e-3 * sv[0]
        x = vt[keep].T @ ((uu[:, keep].T @ np.concatenate(v)) / sv[keep])
        delta = x / scale
        he = he @ exp_twist(delta[:6])
        for n_j, jd in enumerate(cur["joints"]):
            dd = delta[6 + 5 * n_j: 11 + 5 * n_j]
            jd["alpha"] += np.degrees(dd[0])
            jd["a"] += dd[1]
            jd["beta"] += np.degrees(dd[2])
            jd["theta"] += np.degrees(dd[3])
            jd["d"] += dd[4]
        pose, jac = fk_jac(cur, joints[ident])
        eps.append(epsilon(centres_in_base(pose, he, sensor[ident]), local))
    pose_all, _ = fk_jac(cur, joints)
    after = centres_in_base(pose_all, he, sensor)
    vst = {}
    for i, m in enumerate(ms):
        if m["use"] == "validate":
            vst.setdefault(m["station"], []).append(i)
    dist = []
    for r in s.get("reference_distances", []):
        a_, b_ = vst.get(r["from"], []), vst.get(r["to"], [])
        for k in range(min(len(a_), len(b_))):
            dist.append({"from": r["from"], "to": r["to"], "pose": k, "reference": r["distance"],
                         "before": float(np.linalg.norm(before[a_[k]] - before[b_[k]])),
                         "after": float(np.linalg.norm(after[a_[k]] - after[b_[k]]))})

    def stats(e):
        e = np.array(e)
        return {"max": float(np.abs(e).max()), "std": float(e.std(ddof=1)), "rms": float(np.sqrt((e ** 2).mean()))}

    result = {
        "format": "spherecal-result", "version": 1, "session": s.get("name", session_path),
        "hand_eye_initial": he0.tolist(), "hand_eye": he.tolist(),
        "robot": {"name": cur["name"], "joints": cur["joints"], "base": cur["base"].tolist(), "flange": cur["flange"].tolist()},
        "joint_errors": [{k: jd[k] - j0[k] for k in ("alpha", "a", "beta", "theta", "d")} for jd, j0 in zip(cur["joints"], nominal["joints"])],
        "solver": {"method": "paper", "pairs": "disjoint"},
        "iterations": [{"epsilon": float(e)} for e in eps], "epsilon_before": float(eps[0]), "epsilon_after": float(eps[-1]),
        "centres": [{"measurement": m["id"], "station": m["station"], "use": m["use"], "sensor": sensor[i].tolist(),
                     "before": before[i].tolist(), "after": after[i].tolist()} for i, m in enumerate(ms)],
    }
    if dist:
        result["validation"] = {"distances": dist,
                                "before": stats([d["before"] - d["reference"] for d in dist]),
                                "after": stats([d["after"] - d["reference"] for d in dist])}
    json.dump(result, open(result_path, "w"), indent=1)
    print(f"eps {eps[0]:.4f} -> {eps[-1]:.4f} mm after {len(eps) - 1} update(s)"
          + (f"; validation std {result['validation']['before']['std']:.4f} -> {result['validation']['after']['std']:.4f} mm" if dist else ""))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
