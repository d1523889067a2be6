#!/usr/bin/env python3
"""Checks that an exported URDF loads in MuJoCo and PyBullet and moves as predicted.

Usage::

    check_urdf.py URDF EXPECT.json [--sim mujoco|pybullet|both] [--seconds S]

EXPECT.json::

    {"joints": [{"name": "joint_1", "type": "revolute", "value": 0.7, "lower": 0.0, "upper": 0.7}],
     "links": [{"name": "part_1", "position": [x, y, z], "quaternion_xyzw": [x, y, z, w]}],
     "tolerance": {"position_m": 0.001, "angle_deg": 0.1}}

``value`` is the joint value (rad or m) to set; ``links`` hold the expected world pose of each link's URDF
frame once every joint is at its value, with the root link fixed at the world origin.

For each simulator the checker

1. loads the URDF exactly as written (the file is never edited; relative mesh paths resolve against the
   URDF's folder, which both simulators do by themselves for an absolute URDF path) and, in MuJoCo, checks
   every mesh kept all the triangles its file has,
2. checks each expected joint's type and limits against EXPECT.json,
3. sets every joint to its value, runs forward kinematics and compares each link's URDF frame with the
   expected pose (position error in metres, angle of the relative rotation in degrees); MuJoCo also notes
   (without failing) collision shapes of different bodies that overlap at that pose,
4. checks the URDF's inertials survived loading (mass, centre of mass, inertia tensor in the link frame),
5. simulates with gravity and contacts off: each joint with a non-zero range is driven from its lower limit
   to the middle of its range (it must get there), then pushed past its upper limit and then past its
   lower limit (it must stay within each, give or take a small margin).

The MuJoCo settings the URDF needs are in MUJOCO_BLOCK below (src/export/urdf.rs writes it); without that
block the checker still runs and says what MuJoCo did instead.

It prints one JSON object with the results per simulator on stdout and exits 0 only when every check passed
in every simulator; otherwise 1, with one line per failure on stderr naming the simulator, the link or joint
and the size of the error. Bad arguments exit 2.

The simulators' own chatter (PyBullet prints on the C stdout) is sent to stderr so stdout stays one JSON
object; MuJoCo's warnings are collected into the report instead of a MUJOCO_LOG.TXT in the working folder.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# The <mujoco> block MuJoCo needs in the URDF: keep the root link and fixed-joint links as bodies, and take
# mesh paths as written (already the MuJoCo 4 default). Visuals stay discarded (MuJoCo's default): its OBJ
# loader keeps only an OBJ's first group, and physics needs only the collision meshes.
MUJOCO_BLOCK = '<mujoco><compiler strippath="false" fusestatic="false"/></mujoco>'

# Motion test settings shared by both simulators.
REACH_TOL_FRACTION = 0.02  # the driven joint must end within 2 % of its range of the target...
REACH_TOL_MIN = 1e-3  # ...or within this many rad / m, whichever is larger
LIMIT_MARGIN_FRACTION = 0.01  # pushed past its limit, a joint may overshoot by 1 % of its range...
LIMIT_MARGIN_MIN = 1e-3  # ...or this many rad / m
# Relative tolerance on mass and inertia, absolute (m) on the centre of mass. URDF numbers are f32.
INERTIA_REL_TOL = 1e-4
COM_TOL_M = 1e-5


# ---------------------------------------------------------------------------------------------------------
# Small rigid-transform helpers (quaternions are xyzw unless a name says otherwise).


def quat_xyzw_to_matrix(q) -> np.ndarray:
    """Rotation matrix of a (not necessarily unit) quaternion in x, y, z, w order."""
    x, y, z, w = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rpy_to_matrix(rpy) -> np.ndarray:
    """URDF fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def quat_angle_deg(q_xyzw, expected_xyzw) -> float:
    """Angle (degrees) of the rotation between two orientations, sign-of-quaternion independent."""
    a = np.asarray(q_xyzw, dtype=float) / np.linalg.norm(q_xyzw)
    b = np.asarray(expected_xyzw, dtype=float) / np.linalg.norm(expected_xyzw)
    # relative rotation r = a * conj(b); its angle is 2 atan2(|vec(r)|, |w(r)|)
    aw, av = a[3], a[:3]
    bw, bv = b[3], -b[:3]
    rw = aw * bw - av @ bv
    rv = aw * bv + bw * av + np.cross(av, bv)
    return math.degrees(2.0 * math.atan2(np.linalg.norm(rv), abs(rw)))


def wxyz_to_xyzw(q) -> list[float]:
    return [float(q[1]), float(q[2]), float(q[3]), float(q[0])]


# ---------------------------------------------------------------------------------------------------------
# Inputs: EXPECT.json and what the checker itself reads from the URDF (mesh files, inertials, mujoco block).


@dataclass
class Expect:
    joints: list[dict]
    links: list[dict]
    position_tol_m: float
    angle_tol_deg: float


def load_expect(path: Path) -> Expect:
    data = json.loads(path.read_text())
    tol = data.get("tolerance", {})
    joints = data.get("joints", [])
    links = data.get("links", [])
    for j in joints:
        for key in ("name", "type", "value"):
            if key not in j:
                raise ValueError(f"{path}: joint entry {j} lacks '{key}'")
        if j["type"] not in ("revolute", "prismatic", "continuous", "fixed"):
            raise ValueError(f"{path}: joint {j['name']}: unknown type {j['type']!r}")
    for link in links:
        for key in ("name", "position", "quaternion_xyzw"):
            if key not in link:
                raise ValueError(f"{path}: link entry {link} lacks '{key}'")
    return Expect(joints, links, float(tol.get("position_m", 1e-3)), float(tol.get("angle_deg", 0.1)))


@dataclass
class UrdfInfo:
    root: str
    mesh_files: list[str]
    has_mujoco_block: bool
    mujoco_compiler: dict
    # link name -> (mass, com xyz in the link frame, 3x3 inertia about the com in the link frame)
    inertials: dict = field(default_factory=dict)


def read_urdf(path: Path) -> UrdfInfo:
    """The facts the checks need straight from the file, independent of either simulator."""
    root_elem = ET.parse(path).getroot()
    links = [link.get("name") for link in root_elem.findall("link")]
    children = {j.find("child").get("link") for j in root_elem.findall("joint")}
    roots = [name for name in links if name not in children]
    mesh_files = [m.get("filename") for m in root_elem.iter("mesh") if m.get("filename")]
    mj = root_elem.find("mujoco")
    compiler = dict(mj.find("compiler").attrib) if mj is not None and mj.find("compiler") is not None else {}
    inertials = {}
    for link in root_elem.findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        origin = inertial.find("origin")
        xyz = [float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()]
        rpy = [float(v) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()]
        mass = float(inertial.find("mass").get("value"))
        i = {k: float(inertial.find("inertia").get(k, "0")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        tensor = np.array(
            [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        )
        rot = rpy_to_matrix(rpy)
        inertials[link.get("name")] = (mass, np.array(xyz), rot @ tensor @ rot.T)
    return UrdfInfo(
        root=roots[0] if len(roots) == 1 else "",
        mesh_files=mesh_files,
        has_mujoco_block=mj is not None,
        mujoco_compiler=compiler,
        inertials=inertials,
    )


# ---------------------------------------------------------------------------------------------------------
# Result bookkeeping shared by both simulators.


class SimResult:
    """Checks of one simulator: JSON-ready numbers plus the failures, each one line for stderr."""

    def __init__(self, sim: str):
        self.sim = sim
        self.failures: list[str] = []
        self.notes: list[str] = []
        self.data: dict = {"links": {}, "joints": {}, "inertials": {}, "motion": {}}

    def fail(self, message: str) -> None:
        self.failures.append(message)

    def note(self, message: str) -> None:
        self.notes.append(message)

    def as_json(self) -> dict:
        links = self.data["links"].values()
        out = {
            "ok": not self.failures,
            **{k: v for k, v in self.data.items() if k not in ("links", "joints", "inertials", "motion")},
            "max_position_error_m": max((v["position_error_m"] for v in links), default=0.0),
            "max_angle_error_deg": max((v["angle_error_deg"] for v in links), default=0.0),
            "links": self.data["links"],
            "joints": self.data["joints"],
            "inertials": self.data["inertials"],
            "motion": self.data["motion"],
            "failures": self.failures,
            "notes": self.notes,
        }
        return out


def compare_pose(res: SimResult, name: str, pos, quat_xyzw, expected: dict, exp: Expect) -> None:
    """Records the pose error of one link and fails when it is over the tolerances."""
    pos_err = float(np.linalg.norm(np.asarray(pos, dtype=float) - np.asarray(expected["position"], dtype=float)))
    ang_err = quat_angle_deg(quat_xyzw, expected["quaternion_xyzw"])
    res.data["links"][name] = {
        "position": [float(v) for v in pos],
        "quaternion_xyzw": [float(v) for v in quat_xyzw],
        "position_error_m": pos_err,
        "angle_error_deg": ang_err,
    }
    if pos_err > exp.position_tol_m:
        res.fail(f"link {name}: position off by {pos_err:.6g} m (tolerance {exp.position_tol_m:g} m)")
    if ang_err > exp.angle_tol_deg:
        res.fail(f"link {name}: orientation off by {ang_err:.6g} deg (tolerance {exp.angle_tol_deg:g} deg)")


def check_limits(res: SimResult, joint: dict, limited: bool, lower: float, upper: float) -> None:
    """Compares a loaded joint's limits with EXPECT.json (continuous and fixed joints have none)."""
    name = joint["name"]
    entry = res.data["joints"].setdefault(name, {})
    entry.update({"limited": bool(limited), "lower": float(lower), "upper": float(upper)})
    if joint["type"] not in ("revolute", "prismatic") or "lower" not in joint:
        return
    if not limited:
        zero_range = res.sim == "mujoco" and joint["lower"] == joint["upper"]
        why = " (MuJoCo ignores a limit whose lower equals its upper: export it as fixed)" if zero_range else ""
        res.fail(f"joint {name}: loaded without limits{why}; expected [{joint['lower']:g}, {joint['upper']:g}]")
        return
    err = max(abs(lower - joint["lower"]), abs(upper - joint["upper"]))
    entry["limit_error"] = err
    if err > 1e-6 * max(1.0, abs(joint["lower"]), abs(joint["upper"])):
        res.fail(
            f"joint {name}: limits [{lower:.9g}, {upper:.9g}] differ from expected "
            f"[{joint['lower']:.9g}, {joint['upper']:.9g}] by {err:.3g}"
        )


def check_inertial(res: SimResult, link: str, urdf: UrdfInfo, mass: float, com, inertia) -> None:
    """Compares a loaded body's mass, centre of mass and inertia (link frame) with the URDF's inertial."""
    if link not in urdf.inertials:
        return
    want_mass, want_com, want_inertia = urdf.inertials[link]
    mass_err = abs(mass - want_mass) / max(want_mass, 1e-12)
    com_err = float(np.linalg.norm(np.asarray(com) - want_com))
    inertia_err = float(np.abs(np.asarray(inertia) - want_inertia).max() / max(np.abs(want_inertia).max(), 1e-12))
    res.data["inertials"][link] = {
        "mass": mass,
        "mass_rel_error": mass_err,
        "com_error_m": com_err,
        "inertia_rel_error": inertia_err,
    }
    if mass_err > INERTIA_REL_TOL:
        res.fail(f"link {link}: mass {mass:.6g} kg, URDF says {want_mass:.6g} kg (relative error {mass_err:.3g})")
    if com_err > COM_TOL_M:
        res.fail(f"link {link}: centre of mass off by {com_err:.3g} m from the URDF inertial origin")
    if inertia_err > INERTIA_REL_TOL:
        res.fail(f"link {link}: inertia tensor differs from the URDF's by {inertia_err:.3g} (relative)")


def motion_targets(joint: dict) -> tuple[float, float, float, float] | None:
    """(start, middle, past the upper limit, past the lower limit) for the motion test; None for joints
    without a range to move in."""
    if joint["type"] not in ("revolute", "prismatic") or "lower" not in joint:
        return None
    lower, upper = float(joint["lower"]), float(joint["upper"])
    if upper <= lower:
        return None
    return lower, 0.5 * (lower + upper), upper + 0.5 * (upper - lower), lower - 0.5 * (upper - lower)


def judge_motion(res: SimResult, joint: dict, start_q: float, reached: float, pushed: float, pulled: float) -> None:
    """Fails a joint that did not reach the middle of its range, or left it when pushed past either limit."""
    name = joint["name"]
    lower, upper = float(joint["lower"]), float(joint["upper"])
    rng = upper - lower
    mid = 0.5 * (lower + upper)
    reach_tol = max(REACH_TOL_FRACTION * rng, REACH_TOL_MIN)
    margin = max(LIMIT_MARGIN_FRACTION * rng, LIMIT_MARGIN_MIN)
    res.data["motion"][name] = {
        "start": start_q,
        "target": mid,
        "reached": reached,
        "reach_error": abs(reached - mid),
        "pushed_past_upper_to": pushed,
        "pushed_past_lower_to": pulled,
        "overshoot": max(0.0, pushed - upper, lower - pulled),
    }
    if abs(reached - mid) > reach_tol:
        res.fail(
            f"joint {name}: driven from {start_q:.4g} toward {mid:.4g} it reached {reached:.4g} "
            f"(error {abs(reached - mid):.3g}, tolerance {reach_tol:.3g})"
        )
    for which, q, limit, sign in (("upper", pushed, upper, 1.0), ("lower", pulled, lower, -1.0)):
        what = f"joint {name}: driven toward a target past its {which} limit {limit:.4g},"
        if sign * (q - limit) > margin:
            res.fail(f"{what} it went to {q:.4g} (overshoot {abs(q - limit):.3g}, margin {margin:.3g})")
        elif not lower - margin <= q <= upper + margin:
            res.fail(f"{what} it went to {q:.4g}, out of its range at the other end")
        elif sign * (q - mid) < 0.25 * rng:
            res.fail(f"{what} it only got to {q:.4g}")


# ---------------------------------------------------------------------------------------------------------
# MuJoCo


def check_mujoco(urdf_path: Path, urdf: UrdfInfo, exp: Expect, seconds: float) -> SimResult:
    """Loads with mujoco.MjModel.from_xml_path and runs every check with MuJoCo."""
    res = SimResult("mujoco")
    import mujoco

    res.data["version"] = mujoco.__version__
    # MuJoCo appends warnings to MUJOCO_LOG.TXT in the working directory unless a handler takes them.
    warnings: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda msg: warnings.append(str(msg).strip()))
    try:
        _check_mujoco_model(mujoco, res, urdf_path, urdf, exp, seconds)
    finally:
        mujoco.set_mju_user_warning(previous)
    for w in dict.fromkeys(warnings):  # the spec parse and the model load both warn: once each is enough
        res.note(f"MuJoCo warning: {w}")
    res.data["warnings"] = list(dict.fromkeys(warnings))
    return res


def _check_mujoco_model(mujoco, res: SimResult, urdf_path: Path, urdf: UrdfInfo, exp: Expect, seconds: float):
    """The MuJoCo checks proper: load, meshes, joints, poses, contacts (noted), inertials, motion."""
    if not urdf.has_mujoco_block:
        res.note(
            "the URDF has no <mujoco> block: MuJoCo fuses the root link and fixed-joint links into their "
            f"parents; the exporter should write {MUJOCO_BLOCK}"
        )
    t0 = time.perf_counter()
    try:
        # MjSpec.from_file only parses (meshes load when compiling): it tells the effective compiler
        # settings and each mesh asset's file. The checks use the model MjModel.from_xml_path compiles.
        spec = mujoco.MjSpec.from_file(str(urdf_path))
        res.data["compiler"] = {
            "strippath": bool(spec.strippath),
            "fusestatic": bool(spec.compiler.fusestatic),
            "discardvisual": bool(spec.compiler.discardvisual),
        }
        model = mujoco.MjModel.from_xml_path(str(urdf_path))
    except Exception as e:  # MuJoCo raises ValueError with the compiler's message
        res.fail(f"load failed: {str(e).strip()}")
        return
    res.data["load_s"] = round(time.perf_counter() - t0, 4)
    res.data["counts"] = {"bodies": model.nbody, "joints": model.njnt, "geoms": model.ngeom, "meshes": model.nmesh}
    check_mujoco_meshes(res, model, spec, urdf_path.parent)
    data = mujoco.MjData(model)
    body_names = {model.body(i).name for i in range(model.nbody)}

    # Joints: existence, type, limits.
    qadr, dadr = {}, {}
    mistyped = set()
    for joint in exp.joints:
        name = joint["name"]
        if joint["type"] == "fixed":
            # MuJoCo makes no joint for a fixed URDF joint; its child is welded (a body when fusestatic=false).
            if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0:
                res.fail(f"joint {name}: expected fixed, but MuJoCo made a joint of it")
            continue
        try:
            j = model.joint(name)
        except KeyError:
            res.fail(f"joint {name}: not in the MuJoCo model")
            continue
        want = mujoco.mjtJoint.mjJNT_SLIDE if joint["type"] == "prismatic" else mujoco.mjtJoint.mjJNT_HINGE
        got = mujoco.mjtJoint(int(model.jnt_type[j.id]))
        res.data["joints"][name] = {"type": got.name}
        if got not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            res.fail(f"joint {name}: MuJoCo type {got.name}, expected {want.name} for a {joint['type']} joint")
            continue
        # A hinge/slide mix-up still gets its value set: the pose errors below then show what it does.
        qadr[name] = int(model.jnt_qposadr[j.id])
        dadr[name] = int(model.jnt_dofadr[j.id])
        if got != want:
            res.fail(f"joint {name}: MuJoCo type {got.name}, expected {want.name} for a {joint['type']} joint")
            mistyped.add(name)
            continue
        lo, hi = model.jnt_range[j.id]
        check_limits(res, joint, bool(model.jnt_limited[j.id]), float(lo), float(hi))

    # Poses after setting every joint to its value.
    data.qpos[:] = model.qpos0
    for joint in exp.joints:
        if joint["name"] in qadr:
            data.qpos[qadr[joint["name"]]] = joint["value"]
    mujoco.mj_forward(model, data)  # kinematics, and the contacts reported below
    report_mujoco_contacts(res, model, data)
    for link in exp.links:
        name = link["name"]
        if name in body_names:
            b = model.body(name).id
            compare_pose(res, name, data.xpos[b], wxyz_to_xyzw(data.xquat[b]), link, exp)
        elif name == urdf.root:
            # fusestatic merged the root into the world body: its frame is the world origin.
            res.note(f"root link {name} is not a MuJoCo body (fused into the world); compared as the origin")
            compare_pose(res, name, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], link, exp)
        else:
            res.fail(f"link {name}: not a MuJoCo body (fused away? needs fusestatic=\"false\")")

    # Inertials, in each body's own (URDF link) frame.
    for link in urdf.inertials:
        if link not in body_names:
            continue
        b = model.body(link).id
        rot = quat_xyzw_to_matrix(wxyz_to_xyzw(model.body_iquat[b]))
        inertia = rot @ np.diag(model.body_inertia[b]) @ rot.T
        check_inertial(res, link, urdf, float(model.body_mass[b]), model.body_ipos[b], inertia)

    # Motion: gravity and contacts off (the links' collision shapes may overlap each other, which would jam
    # or fling the joints: that is reported above, not tested here), a PD force in qfrc_applied scaled by
    # each dof's inertia (critically damped, 1 Hz natural frequency), first to the middle of the range,
    # then toward a target past the upper limit, then toward one past the lower limit.
    driven = [
        (j, t)
        for j in exp.joints
        if j["name"] in qadr and j["name"] not in mistyped and (t := motion_targets(j)) is not None
    ]
    if driven:
        model.opt.gravity[:] = 0.0
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        mujoco.mj_resetData(model, data)
        for joint, targets in driven:
            data.qpos[qadr[joint["name"]]] = targets[0]
        mujoco.mj_forward(model, data)
        omega = 2.0 * math.pi
        steps = max(1, int(round(seconds / model.opt.timestep)))
        t0 = time.perf_counter()
        reached, pushed = {}, {}
        for phase in (1, 2, 3):
            for _ in range(steps):
                data.qfrc_applied[:] = 0.0
                for joint, targets in driven:
                    q, v = data.qpos[qadr[joint["name"]]], data.qvel[dadr[joint["name"]]]
                    m_ii = max(float(model.dof_M0[dadr[joint["name"]]]), 1e-9)
                    data.qfrc_applied[dadr[joint["name"]]] = m_ii * (
                        omega * omega * (targets[phase] - q) - 2.0 * omega * v
                    )
                mujoco.mj_step(model, data)
            q_now = {j["name"]: float(data.qpos[qadr[j["name"]]]) for j, _ in driven}
            if phase == 1:
                reached = q_now
            elif phase == 2:
                pushed = q_now
        res.data["simulate_s"] = round(time.perf_counter() - t0, 4)
        for joint, targets in driven:
            name = joint["name"]
            judge_motion(res, joint, targets[0], reached[name], pushed[name], float(data.qpos[qadr[name]]))
        if not np.all(np.isfinite(data.qpos)):
            res.fail("simulation diverged (non-finite qpos)")


def file_triangles(path: Path) -> int | None:
    """Triangles in a binary STL (its header count) or an OBJ (a polygon of n corners is n - 2), else None."""
    suffix = path.suffix.lower()
    if suffix == ".stl":
        with path.open("rb") as f:
            head = f.read(84)
        return int.from_bytes(head[80:84], "little") if len(head) == 84 else None
    if suffix == ".obj":
        with path.open() as f:
            return sum(max(len(line.split()) - 3, 0) for line in f if line.startswith("f "))
    return None


def check_mujoco_meshes(res: SimResult, model, spec, folder: Path) -> None:
    """Fails meshes MuJoCo loaded with fewer triangles than the file has.

    MuJoCo's OBJ reader keeps only the first `o`/`g` group's faces (all vertices, so nothing looks wrong
    until the mesh is drawn or collides); a file's faces must be in one group (`usemtl` switches are fine).
    """
    meshes = {}
    for m in spec.meshes:
        path = folder / spec.meshdir / m.file
        want = file_triangles(path) if path.is_file() else None
        got = int(model.mesh_facenum[model.mesh(m.name).id])
        meshes[m.file] = {"file_triangles": want, "mujoco_faces": got}
        if want is not None and got != want:
            res.fail(
                f"mesh {m.file}: MuJoCo loaded {got} of its {want} triangles "
                "(MuJoCo reads only the first o/g group of an OBJ)"
            )
    res.data["meshes"] = meshes


def report_mujoco_contacts(res: SimResult, model, data) -> None:
    """Notes (does not fail) collision geoms of different bodies that overlap at the checked pose.

    MuJoCo only filters contacts between a body and its parent, so overlapping collision shapes of
    siblings (or of a link and the fused root) push each other apart as soon as the model is simulated.
    """
    import mujoco

    worst: dict[tuple[str, str], float] = {}
    for c in data.contact[: data.ncon]:
        pair = tuple(sorted(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g]) or "world"
                            for g in c.geom))
        worst[pair] = max(worst.get(pair, 0.0), -float(c.dist))
    deep = {f"{a}|{b}": d for (a, b), d in worst.items() if d > 1e-3}
    res.data["contacts_at_pose"] = {"count": int(data.ncon), "penetration_over_1mm_m": deep}
    if deep:
        pairs = ", ".join(f"{k} {v * 1000:.1f} mm" for k, v in sorted(deep.items(), key=lambda kv: -kv[1])[:5])
        res.note(f"collision shapes overlap at the checked pose (body pairs, depth): {pairs}")


# ---------------------------------------------------------------------------------------------------------
# PyBullet


def pose_mul(a, b):
    """Composes two (position, xyzw quaternion) poses: a * b."""
    ra = quat_xyzw_to_matrix(a[1])
    return np.asarray(a[0]) + ra @ np.asarray(b[0]), ra @ quat_xyzw_to_matrix(b[1])


def matrix_to_quat_xyzw(r) -> list[float]:
    """Quaternion (xyzw) of a rotation matrix (Shepperd's method)."""
    t = np.trace(r)
    if t > 0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0, 0.0, 0.0, (r[k, j] - r[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (r[j, i] + r[i, j]) / s
        q[k] = (r[k, i] + r[i, k]) / s
    return q


def check_pybullet(urdf_path: Path, urdf: UrdfInfo, exp: Expect, seconds: float) -> SimResult:
    """Loads with pybullet.loadURDF (DIRECT, fixed base, inertia from the file) and runs every check."""
    res = SimResult("pybullet")
    import pybullet as p

    res.data["version"] = p.getAPIVersion()
    client = p.connect(p.DIRECT)
    try:
        # File caching keys on the path only: a rewritten URDF at the same path would load stale otherwise.
        p.setPhysicsEngineParameter(enableFileCaching=0, physicsClientId=client)
        p.setGravity(0, 0, 0, physicsClientId=client)
        t0 = time.perf_counter()
        try:
            body = p.loadURDF(
                str(urdf_path),
                useFixedBase=True,
                # Without USE_INERTIA_FROM_FILE PyBullet recomputes inertia from the collision shapes.
                flags=p.URDF_USE_INERTIA_FROM_FILE | p.URDF_MAINTAIN_LINK_ORDER,
                physicsClientId=client,
            )
        except p.error as e:
            res.fail(f"load failed: {e} (PyBullet prints the reason, if any, on stderr)")
            return res
        res.data["load_s"] = round(time.perf_counter() - t0, 4)
        _check_pybullet_body(p, client, body, res, urdf, exp, seconds)
    finally:
        p.disconnect(physicsClientId=client)
    return res


def _check_pybullet_body(p, client, body, res: SimResult, urdf: UrdfInfo, exp: Expect, seconds: float) -> None:
    kw = {"physicsClientId": client}
    n = p.getNumJoints(body, **kw)
    base_name = p.getBodyInfo(body, **kw)[0].decode()
    joint_index, link_index = {}, {base_name: -1}
    infos = {}
    for i in range(n):
        info = p.getJointInfo(body, i, **kw)
        joint_index[info[1].decode()] = i
        link_index[info[12].decode()] = i
        infos[i] = info
    res.data["counts"] = {"joints": n}

    # Joints: existence, type, limits.
    want_type = {"revolute": p.JOINT_REVOLUTE, "continuous": p.JOINT_REVOLUTE, "prismatic": p.JOINT_PRISMATIC,
                 "fixed": p.JOINT_FIXED}
    type_name = {p.JOINT_REVOLUTE: "REVOLUTE", p.JOINT_PRISMATIC: "PRISMATIC", p.JOINT_FIXED: "FIXED"}
    movable, posed = {}, {}
    for joint in exp.joints:
        name = joint["name"]
        if name not in joint_index:
            res.fail(f"joint {name}: not in the PyBullet body")
            continue
        i = joint_index[name]
        got = infos[i][2]
        res.data["joints"][name] = {"type": type_name.get(got, str(got))}
        if got != want_type[joint["type"]]:
            res.fail(f"joint {name}: PyBullet type {type_name.get(got, got)}, expected {joint['type']}")
            if got in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
                posed[name] = i  # still set its value: the pose errors then show what the mix-up does
            continue
        if joint["type"] == "fixed":
            continue
        posed[name] = i
        lower, upper = float(infos[i][8]), float(infos[i][9])
        # PyBullet enforces a limit only when lower <= upper (it reads a missing <limit> as 0, -1).
        check_limits(res, joint, lower <= upper and joint["type"] != "continuous", lower, upper)
        movable[name] = i

    # Poses: [4]/[5] of getLinkState are the URDF link frame ([0]/[1] are the centre of mass).
    for joint in exp.joints:
        if joint["name"] in posed:
            p.resetJointState(body, posed[joint["name"]], joint["value"], 0.0, **kw)
    for link in exp.links:
        name = link["name"]
        if name not in link_index:
            res.fail(f"link {name}: not in the PyBullet body")
            continue
        i = link_index[name]
        if i == -1:
            # The base pose PyBullet reports is its centre of mass; undo the local inertial frame.
            com = p.getBasePositionAndOrientation(body, **kw)
            dyn = p.getDynamicsInfo(body, -1, **kw)
            inv_pos, inv_orn = p.invertTransform(dyn[3], dyn[4])
            pos, rot = pose_mul(com, (inv_pos, inv_orn))
            compare_pose(res, name, pos, matrix_to_quat_xyzw(rot), link, exp)
        else:
            state = p.getLinkState(body, i, computeForwardKinematics=True, **kw)
            compare_pose(res, name, state[4], state[5], link, exp)

    # Inertials: getDynamicsInfo gives mass, principal moments and the principal frame in the link frame.
    for link in urdf.inertials:
        if link not in link_index:
            continue
        i = link_index[link]
        dyn = p.getDynamicsInfo(body, i, **kw)
        if i == -1:
            res.note(f"root link {link}: PyBullet zeroes a fixed base's mass; its inertial is not compared")
            continue
        rot = quat_xyzw_to_matrix(dyn[4])
        check_inertial(res, link, urdf, float(dyn[0]), dyn[3], rot @ np.diag(dyn[2]) @ rot.T)

    # Motion: POSITION_CONTROL from the lower limit to the middle of the range, then toward a target past
    # the upper limit, then toward one past the lower limit. PyBullet's position motor is a velocity
    # constraint (target velocity proportional to the position error) capped by a force; the cap is
    # 1000 s^-2 times the joint's diagonal mass-matrix entry so any link gets there, rather than the URDF
    # effort (which says nothing about the link's mass).
    # Self-collision is off (PyBullet's default without URDF_USE_SELF_COLLISION) and there is no other body.
    driven = [(j, t) for j in exp.joints if j["name"] in movable and (t := motion_targets(j)) is not None]
    if not driven:
        return
    idx = [movable[j["name"]] for j, _ in driven]
    for (_, targets), i in zip(driven, idx):
        p.resetJointState(body, i, targets[0], 0.0, **kw)
    # calculateMassMatrix takes every movable joint's position, in joint-index order.
    dof = [i for i in range(n) if infos[i][2] != p.JOINT_FIXED]
    mass_matrix = np.array(
        p.calculateMassMatrix(body, [p.getJointState(body, i, **kw)[0] for i in dof], **kw)
    )
    forces = [1000.0 * max(float(mass_matrix[dof.index(i), dof.index(i)]), 1e-6) for i in idx]
    dt = 1.0 / 240.0
    p.setTimeStep(dt, **kw)
    steps = max(1, int(round(seconds / dt)))
    t0 = time.perf_counter()
    states = []  # joint positions after each phase
    for phase in (1, 2, 3):
        p.setJointMotorControlArray(
            body, idx, p.POSITION_CONTROL, targetPositions=[t[phase] for _, t in driven], forces=forces, **kw
        )
        for _ in range(steps):
            p.stepSimulation(**kw)
        states.append([float(p.getJointState(body, i, **kw)[0]) for i in idx])
    res.data["simulate_s"] = round(time.perf_counter() - t0, 4)
    for k, (joint, targets) in enumerate(driven):
        judge_motion(res, joint, targets[0], states[0][k], states[1][k], states[2][k])


# ---------------------------------------------------------------------------------------------------------
# Driver


@contextlib.contextmanager
def stdout_to_stderr():
    """Points file descriptor 1 at stderr (C libraries print there) and yields the real stdout."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    real_stdout = os.fdopen(os.dup(saved), "w")
    try:
        yield real_stdout
    finally:
        real_stdout.close()
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def finish_report(tool: str, report: dict, failures: list[str], real_stdout) -> int:
    """Adds the verdict to `report`, prints each failure on stderr and the report on stdout; the
    exit status: 0 when nothing failed, else 1."""
    report["ok"] = not failures
    report["failures"] = failures
    for f in failures:
        print(f"{tool}: FAIL {f}", file=sys.stderr)
    json.dump(report, real_stdout, indent=1)
    real_stdout.write("\n")
    return 0 if not failures else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("urdf", type=Path)
    parser.add_argument("expect", type=Path)
    parser.add_argument("--sim", choices=("both", "mujoco", "pybullet"), default="both")
    parser.add_argument("--seconds", type=float, default=1.5, help="simulated seconds per motion phase")
    args = parser.parse_args(argv)

    with stdout_to_stderr() as real_stdout:
        started = time.perf_counter()
        urdf_path = args.urdf.resolve()
        try:
            exp = load_expect(args.expect)
            urdf = read_urdf(urdf_path)
        except (OSError, ValueError, ET.ParseError, AttributeError) as e:
            print(f"check_urdf: cannot read the inputs: {e}", file=sys.stderr)
            return 2
        report: dict = {
            "urdf": str(urdf_path),
            "root_link": urdf.root,
            # attributes of the URDF's <mujoco><compiler>, or null without a <mujoco> block
            "mujoco_block_compiler": urdf.mujoco_compiler if urdf.has_mujoco_block else None,
        }
        failures: list[str] = []
        missing = [f for f in urdf.mesh_files if not (urdf_path.parent / f).is_file()]
        if missing:
            failures.append(f"urdf: mesh files missing next to the URDF: {', '.join(missing)}")
        sims = ("mujoco", "pybullet") if args.sim == "both" else (args.sim,)
        for sim in sims:
            t0 = time.perf_counter()
            checker = check_mujoco if sim == "mujoco" else check_pybullet
            try:
                res = checker(urdf_path, urdf, exp, args.seconds)
            except ImportError as e:
                res = SimResult(sim)
                res.fail(f"not installed ({e}); run scripts/setup.sh")
            except Exception as e:  # a checker bug or an unexpected simulator error: report, don't hide
                res = SimResult(sim)
                res.fail(f"checker error: {type(e).__name__}: {e}")
            report[sim] = res.as_json()
            report[sim]["total_s"] = round(time.perf_counter() - t0, 4)
            failures += [f"{sim}: {f}" for f in res.failures]
            for note in res.notes:
                print(f"check_urdf: note: {sim}: {note}", file=sys.stderr)
        report["total_s"] = round(time.perf_counter() - started, 4)
        return finish_report("check_urdf", report, failures, real_stdout)


if __name__ == "__main__":
    sys.exit(main())
