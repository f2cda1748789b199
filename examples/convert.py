#!/usr/bin/env python3
"""Writes the example files of the user guide that spherecal cannot write
itself: the same poses in other layouts, and targets to compensate.
Called by examples/make.sh (read it first); plain Python 3, no packages.

    python3 examples/convert.py TMP

TMP holds what make.sh simulated: cell.result.json (the seed-7 cell's ml
result) and log/ (`spherecal simulate --csv-out` of a small cell).
Writes into examples/ (the current folder is the repository's root):

- poses/: the 15 FANUC flange poses of data/robcalibrator-sphere/RobPoses.rob
  in six more layouts (table without and with a header, FANUC .ls, ABB
  RAPID, KUKA .dat, URScript), the numbers converted, nothing else changed;
- log/: the small cell's joint log as a cell writes it (own column names,
  semicolons and decimal commas, joints in radians, KUKA A B C flange
  poses) and its profiles in micrometres, space-separated, no header;
- targets.csv, targets-matrix.txt and path.mod: the sensor poses along the
  stepped-block scan of examples/scan (its nominal flange poses times the
  seed-7 cell's calibrated hand-eye), as an ABB table, three of them as
  4x4 matrices, and as a RAPID module.
"""

import csv
import json
import math
import os
import sys


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, 0, s], [0, 1, 0], [-s, 0, c]]


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def zyx(rz, ry, rx):
    """R = Rz(rz)·Ry(ry)·Rx(rx), angles in degrees (FANUC r p w, KUKA A B C)."""
    d = math.radians
    return mul(mul(rot_z(d(rz)), rot_y(d(ry))), rot_x(d(rx)))


def angles_zyx(r):
    """(rz, ry, rx) in degrees of R = Rz·Ry·Rx."""
    ry = math.asin(max(-1.0, min(1.0, -r[2][0])))
    rz = math.atan2(r[1][0], r[0][0])
    rx = math.atan2(r[2][1], r[2][2])
    return math.degrees(rz), math.degrees(ry), math.degrees(rx)


def quaternion(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix, w >= 0."""
    t = r[0][0] + r[1][1] + r[2][2]
    if t > 0:
        s = 2 * math.sqrt(t + 1)
        q = [s / 4, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s]
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = 2 * math.sqrt(1 + r[0][0] - r[1][1] - r[2][2])
        q = [(r[2][1] - r[1][2]) / s, s / 4, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s]
    elif r[1][1] > r[2][2]:
        s = 2 * math.sqrt(1 + r[1][1] - r[0][0] - r[2][2])
        q = [(r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, s / 4, (r[1][2] + r[2][1]) / s]
    else:
        s = 2 * math.sqrt(1 + r[2][2] - r[0][0] - r[1][1])
        q = [(r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, s / 4]
    if q[0] < 0:
        q = [-v for v in q]
    return q


def from_quaternion(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def rotation_vector(r):
    """Axis times angle (rad) of a rotation matrix (UR's rx ry rz)."""
    q = quaternion(r)
    s = math.sqrt(q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    if s < 1e-12:
        return [0.0, 0.0, 0.0]
    angle = 2 * math.atan2(s, q[0])
    return [angle * v / s for v in q[1:]]


def write(path, text):
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)


def pose_files():
    """The real set's poses in every layout the import reads."""
    with open("data/robcalibrator-sphere/RobPoses.rob", encoding="utf-8") as f:
        poses = json.load(f)["RobPoses"]
    os.makedirs("examples/poses", exist_ok=True)
    n = len(poses)
    # A table without a header, spaces (as RobCalibrator's Robot.txt).
    write(
        "examples/poses/robposes.txt",
        "".join(" ".join(f"{v:.3f}" for v in p) + "\n" for p in poses),
    )
    # A table with a header: semicolons and decimal commas (a European spreadsheet).
    rows = ["id;X;Y;Z;W;P;R"]
    for k, p in enumerate(poses):
        rows.append(f"p{k + 1};" + ";".join(f"{v:.3f}".replace(".", ",") for v in p))
    write("examples/poses/robposes.csv", "\n".join(rows) + "\n")
    # FANUC TP: /MN moves through P[1..n], /POS holds them.
    ls = "/PROG  CALIB_SPH\n/ATTR\nOWNER\t\t= MNEDITOR;\nCOMMENT\t\t= \"sphere poses\";\nDEFAULT_GROUP\t= 1,*,*,*,*;\n/MN\n"
    ls += "   1:  UFRAME_NUM=0 ;\n   2:  UTOOL_NUM=0 ;\n"
    for k in range(n):
        ls += f"{k + 3:>4}:J P[{k + 1}] 20% FINE    ;\n"
    ls += "/POS\n"
    for k, p in enumerate(poses):
        ls += (
            f"P[{k + 1}]{{\n   GP1:\n\tUF : 0, UT : 0,\t\tCONFIG : 'N U T, 0, 0, 0',\n"
            f"\tX = {p[0]:>10.3f}  mm,\tY = {p[1]:>10.3f}  mm,\tZ = {p[2]:>10.3f}  mm,\n"
            f"\tW = {p[3]:>10.3f} deg,\tP = {p[4]:>10.3f} deg,\tR = {p[5]:>10.3f} deg\n}};\n"
        )
    ls += "/END\n"
    write("examples/poses/calib_sph.ls", ls)
    # ABB RAPID: robtargets of tool0 (the flange), quaternion w first.
    mod = "MODULE SpherePoses\n  ! the 15 flange poses of data/robcalibrator-sphere, tool0\n"
    for k, p in enumerate(poses):
        q = quaternion(zyx(p[5], p[4], p[3]))
        mod += (
            f"  CONST robtarget p{k + 1} := [[{p[0]:.3f},{p[1]:.3f},{p[2]:.3f}],"
            f"[{q[0]:.7f},{q[1]:.7f},{q[2]:.7f},{q[3]:.7f}],[0,0,0,0],"
            "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\n"
        )
    mod += "  PROC main()\n"
    for k in range(n):
        mod += f"    MoveL p{k + 1}, v50, fine, tool0;\n"
    mod += "  ENDPROC\nENDMODULE\n"
    write("examples/poses/robposes.mod", mod)
    # KUKA KRL .dat: E6POS, A B C = Rz Ry Rx (FANUC's R P W).
    dat = "&ACCESS RVP\nDEFDAT  SPHEREPOSES\n"
    for k, p in enumerate(poses):
        dat += (
            f"DECL E6POS XP{k + 1}={{X {p[0]:.3f},Y {p[1]:.3f},Z {p[2]:.3f},"
            f"A {p[5]:.3f},B {p[4]:.3f},C {p[3]:.3f},S 2,T 0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\n"
        )
    dat += "ENDDAT\n"
    write("examples/poses/robposes.dat", dat)
    # URScript: p[x, y, z, rx, ry, rz] in m and rad, moved to in order.
    ur = "def sphere_poses():\n"
    for k, p in enumerate(poses):
        v = rotation_vector(zyx(p[5], p[4], p[3]))
        ur += (
            f"  global p{k + 1} = p[{p[0] / 1000:.6f}, {p[1] / 1000:.6f}, {p[2] / 1000:.6f}, "
            f"{v[0]:.6f}, {v[1]:.6f}, {v[2]:.6f}]\n"
        )
    for k in range(n):
        ur += f"  movel(p{k + 1}, a=0.5, v=0.05)\n"
    ur += "end\n"
    write("examples/poses/robposes.script", ur)


def comma(v, digits):
    return f"{v:.{digits}f}".replace(".", ",")


def joint_log(tmp):
    """The small simulated cell's log, as a cell with its own names writes it."""
    src = os.path.join(tmp, "log")
    os.makedirs("examples/log/profiles", exist_ok=True)
    with open(os.path.join(src, "joints.csv"), encoding="utf-8") as f:
        lines = [l for l in f if not l.startswith("#")]
    out = ["Pose;Sphere;Use;Side;A1;A2;A3;A4;A5;A6;X;Y;Z;A;B;C"]
    for row in csv.DictReader(lines):
        joints = [comma(math.radians(float(row[f"j{k}"])), 9) for k in range(1, 7)]
        r = from_quaternion([float(row[k]) for k in ("q1", "q2", "q3", "q4")])
        a, b, c = angles_zyx(r)
        xyz = [comma(float(row[k]), 3) for k in ("x", "y", "z")]
        abc = [comma(v, 4) for v in (a, b, c)]
        out.append(";".join([row["id"], row["station"], row["use"], row["side"]] + joints + xyz + abc))
        with open(os.path.join(src, "profiles", row["id"] + ".csv"), encoding="utf-8") as f:
            points = list(csv.DictReader(f))
        write(
            f"examples/log/profiles/{row['id']}.txt",
            "".join(f"{float(p['y']) * 1000:.0f} {float(p['z']) * 1000:.0f}\n" for p in points),
        )
    write("examples/log/log.csv", "\n".join(out) + "\n")
    with open(os.path.join(src, "references.csv"), encoding="utf-8") as f:
        write("examples/log/references.csv", f.read())


def targets(tmp):
    """Sensor poses along the stepped-block scan: a path to compensate."""
    with open(os.path.join(tmp, "cell.result.json"), encoding="utf-8") as f:
        he = json.load(f)["hand_eye"]
    with open("examples/scan/joints.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith("#")))
    table = ["id,x,y,z,q1,q2,q3,q4"]
    hq = quaternion([h[:3] for h in he[:3]])
    mod = (
        "MODULE ScanPath\n  ! the sensor along the stepped-block scan of examples/scan\n"
        f"  PERS tooldata tSensor := [TRUE,[[{he[0][3]:.2f},{he[1][3]:.2f},{he[2][3]:.2f}],"
        f"[{hq[0]:.5f},{hq[1]:.5f},{hq[2]:.5f},{hq[3]:.5f}]],[1,[0,0,1],[1,0,0,0],0,0,0]];\n"
    )
    names = []
    matrices = []
    for k, row in enumerate(rows):
        r = from_quaternion([float(row[c]) for c in ("q1", "q2", "q3", "q4")])
        t = [float(row[c]) for c in ("x", "y", "z")]
        rs = mul(r, [h[:3] for h in he[:3]])
        ts = [t[i] + sum(r[i][j] * he[j][3] for j in range(3)) for i in range(3)]
        q = quaternion(rs)
        name = f"T{k + 1}"
        names.append(name)
        if k in (0, 4, 9):
            matrices.append((name, [rs[i] + [ts[i]] for i in range(3)]))
        table.append(f"{name},{ts[0]:.3f},{ts[1]:.3f},{ts[2]:.3f}," + ",".join(f"{v:.7f}" for v in q))
        joints = [float(row[f"j{i}"]) for i in range(1, 7)]
        cf = [math.floor(joints[0] / 90), math.floor(joints[3] / 90), math.floor(joints[5] / 90), int(joints[4] < 0)]
        mod += (
            f"  CONST robtarget {name} := [[{ts[0]:.3f},{ts[1]:.3f},{ts[2]:.3f}],"
            f"[{q[0]:.7f},{q[1]:.7f},{q[2]:.7f},{q[3]:.7f}],[{cf[0]},{cf[1]},{cf[2]},{cf[3]}],"
            "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\n"
        )
    mod += "  PROC main()\n"
    for k, name in enumerate(names):
        mod += f"    MoveL {name}, v100, {'fine' if k in (0, len(names) - 1) else 'z1'}, tSensor;\n"
    mod += "  ENDPROC\nENDMODULE\n"
    write("examples/targets.csv", "\n".join(table) + "\n")
    # Three of them as 4x4 matrices (row-major, mm), an id first, no header.
    rows = []
    for name, m in matrices:
        cells = [f"{v:.9f}" for v in m[0][:3]] + [f"{m[0][3]:.3f}"]
        cells += [f"{v:.9f}" for v in m[1][:3]] + [f"{m[1][3]:.3f}"]
        cells += [f"{v:.9f}" for v in m[2][:3]] + [f"{m[2][3]:.3f}"]
        cells += ["0", "0", "0", "1"]
        rows.append(" ".join([name] + cells))
    write("examples/targets-matrix.txt", "\n".join(rows) + "\n")
    write("examples/path.mod", mod)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: python3 examples/convert.py TMP (see examples/make.sh)")
    tmp = sys.argv[1]
    pose_files()
    joint_log(tmp)
    targets(tmp)


if __name__ == "__main__":
    main()
