#!/usr/bin/env python3
"""Checks that an exported twin behaves in MuJoCo and PyBullet with contacts on.

Usage::

    check_contacts.py URDF [--sim mujoco|pybullet|both] [--max-penetration-mm 5] [--min-reach 0.9]
                      [--seconds S]

For each simulator, with gravity off and the root link fixed:

1. **At rest** (every joint at 0, the start state): the deepest overlap between the collision shapes
   of a movable link and those of any other link. MuJoCo collides a link with its parent when the
   parent is welded to the world, as a twin's base is; PyBullet is loaded with self-collision on,
   parents included (``URDF_USE_SELF_COLLISION_INCLUDE_PARENT``: without it a drawer and its cabinet
   never touch). It must be at most ``--max-penetration-mm``.
2. **Driving each joint**: one joint at a time, a position actuator (MuJoCo: an ``actuator`` added
   to the model, gains scaled by the joint's inertia, 1 Hz, critically damped; PyBullet:
   ``POSITION_CONTROL`` with a force cap scaled the same way) drives it from 0 to the other end of
   its range and back, while the other joints' actuators hold them at 0. Each way it must cover at
   least ``--min-reach`` of the range; the deepest overlap on the way is reported.

Prints one JSON object on stdout (per simulator: the rest overlap by link pair, and per joint the
fractions reached and the overlap on the way) and exits 0 only when every check passed; otherwise
1, with one line per failure on stderr. Bad arguments exit 2.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_urdf import finish_report, read_urdf, stdout_to_stderr  # noqa: E402

OMEGA = 2.0 * 3.141592653589793  # actuator natural frequency (rad/s)


class Result:
    """One simulator's numbers and failures."""

    def __init__(self, sim: str):
        self.sim = sim
        self.failures: list[str] = []
        self.data: dict = {"rest": {}, "joints": {}}

    def as_json(self) -> dict:
        return {"ok": not self.failures, **self.data, "failures": self.failures}


def judge(res: Result, args, rest_mm: float, pairs: dict, joints: dict) -> None:
    """Records the figures and fails what is over the limits."""
    res.data["rest"] = {"max_penetration_mm": rest_mm, "pairs_mm": pairs}
    res.data["joints"] = joints
    if rest_mm > args.max_penetration_mm:
        worst = max(pairs, key=pairs.get)
        res.failures.append(
            f"at rest {worst} overlap by {rest_mm:.2f} mm (at most {args.max_penetration_mm:g} mm)"
        )
    for name, j in joints.items():
        for way in ("forward", "back"):
            if j[f"{way}_reach"] < args.min_reach:
                res.failures.append(
                    f"joint {name}: driven {way} across [{j['lower']:.4g}, {j['upper']:.4g}] it covered "
                    f"{100 * j[f'{way}_reach']:.1f} % of the range (at least {100 * args.min_reach:g} %)"
                )


def far_end(lower: float, upper: float) -> float:
    """The end of a twin's range away from 0 (the start state sits at one end)."""
    return upper if abs(upper) >= abs(lower) else lower


# ---------------------------------------------------------------------------------------------------------
# MuJoCo


def check_mujoco(urdf_path: Path, args) -> Result:
    import mujoco

    res = Result("mujoco")
    res.data["version"] = mujoco.__version__
    spec = mujoco.MjSpec.from_file(str(urdf_path))
    joints = [j for j in spec.joints if j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)]
    for j in joints:
        act = spec.add_actuator()
        act.name = f"servo_{j.name}"
        act.target = j.name
        act.trntype = mujoco.mjtTrn.mjTRN_JOINT
        act.set_to_position(kp=1.0)
    t0 = time.perf_counter()
    model = spec.compile()
    res.data["load_s"] = round(time.perf_counter() - t0, 4)
    res.data["geoms"] = int(model.ngeom)
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    names = {j.name: (int(model.joint(j.name).qposadr[0]), int(model.joint(j.name).dofadr[0])) for j in joints}
    for a, j in enumerate(joints):
        m_ii = max(float(model.dof_M0[names[j.name][1]]), 1e-9)
        kp, kv = m_ii * OMEGA * OMEGA, 2.0 * m_ii * OMEGA
        model.actuator_gainprm[a, 0] = kp
        model.actuator_biasprm[a, :3] = [0.0, -kp, -kv]
        model.actuator_ctrllimited[a] = 0
        model.actuator_forcelimited[a] = 0

    def overlaps() -> dict:
        worst: dict[str, float] = {}
        for c in data.contact[: data.ncon]:
            bodies = sorted(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g]) or "world"
                            for g in c.geom)
            key = "|".join(bodies)
            worst[key] = max(worst.get(key, 0.0), -1000.0 * float(c.dist))
        return worst

    rest = overlaps()
    steps = max(1, int(round(args.seconds / model.opt.timestep)))
    report = {}
    for a, j in enumerate(joints):
        qadr, _ = names[j.name]
        lower, upper = (float(v) for v in model.jnt_range[model.joint(j.name).id])
        end = far_end(lower, upper)
        mujoco.mj_resetData(model, data)
        deepest = 0.0
        reached = []
        for target in (end, 0.0):
            data.ctrl[:] = 0.0
            data.ctrl[a] = target
            for _ in range(steps):
                mujoco.mj_step(model, data)
                deepest = max([deepest, *overlaps().values()])
            reached.append(float(data.qpos[qadr]))
        report[j.name] = way_report(lower, upper, end, reached, deepest)
    judge(res, args, max(rest.values(), default=0.0), rest, report)
    return res


def way_report(lower: float, upper: float, end: float, reached: list[float], deepest: float) -> dict:
    """Fractions of the range covered going to the far end and coming back to 0."""
    span = max(abs(end), 1e-12)
    return {
        "lower": lower,
        "upper": upper,
        "forward_to": reached[0],
        "back_to": reached[1],
        "forward_reach": max(0.0, min(1.0, reached[0] / end)) if end else 1.0,
        "back_reach": max(0.0, min(1.0, (reached[0] - reached[1]) / end)) if end else 1.0,
        "max_penetration_mm": deepest,
        "range": span,
    }


# ---------------------------------------------------------------------------------------------------------
# PyBullet


def check_pybullet(urdf_path: Path, args) -> Result:
    import numpy as np
    import pybullet as p

    res = Result("pybullet")
    client = p.connect(p.DIRECT)
    kw = {"physicsClientId": client}
    try:
        p.setPhysicsEngineParameter(enableFileCaching=0, **kw)
        p.setGravity(0, 0, 0, **kw)
        flags = (p.URDF_USE_SELF_COLLISION | p.URDF_USE_SELF_COLLISION_INCLUDE_PARENT
                 | p.URDF_USE_INERTIA_FROM_FILE | p.URDF_MAINTAIN_LINK_ORDER)
        t0 = time.perf_counter()
        body = p.loadURDF(str(urdf_path), useFixedBase=True, flags=flags, **kw)
        res.data["load_s"] = round(time.perf_counter() - t0, 4)
        n = p.getNumJoints(body, **kw)
        infos = [p.getJointInfo(body, i, **kw) for i in range(n)]
        link_name = {-1: p.getBodyInfo(body, **kw)[0].decode(), **{i: infos[i][12].decode() for i in range(n)}}
        movable = [i for i in range(n) if infos[i][2] in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC)]

        def overlaps() -> dict:
            worst: dict[str, float] = {}
            for c in p.getClosestPoints(body, body, 0.0, **kw):
                a, b = c[3], c[4]
                if a == b:
                    continue
                key = "|".join(sorted((link_name[a], link_name[b])))
                worst[key] = max(worst.get(key, 0.0), -1000.0 * float(c[8]))
            return worst

        p.performCollisionDetection(**kw)
        rest = overlaps()
        dof = [i for i in range(n) if infos[i][2] != p.JOINT_FIXED]
        mass = np.array(p.calculateMassMatrix(body, [0.0] * len(dof), **kw))
        forces = [1000.0 * max(float(mass[dof.index(i), dof.index(i)]), 1e-6) for i in movable]
        dt = 1.0 / 240.0
        p.setTimeStep(dt, **kw)
        steps = max(1, int(round(args.seconds / dt)))
        report = {}
        for k, i in enumerate(movable):
            lower, upper = float(infos[i][8]), float(infos[i][9])
            end = far_end(lower, upper)
            for m in movable:
                p.resetJointState(body, m, 0.0, 0.0, **kw)
            deepest = 0.0
            reached = []
            for target in (end, 0.0):
                targets = [target if m == i else 0.0 for m in movable]
                p.setJointMotorControlArray(body, movable, p.POSITION_CONTROL, targetPositions=targets,
                                            forces=forces, **kw)
                for s in range(steps):
                    p.stepSimulation(**kw)
                    if s % 8 == 0:
                        deepest = max([deepest, *overlaps().values()])
                reached.append(float(p.getJointState(body, i, **kw)[0]))
            report[infos[i][1].decode()] = way_report(lower, upper, end, reached, deepest)
        judge(res, args, max(rest.values(), default=0.0), rest, report)
    finally:
        p.disconnect(**kw)
    return res


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("urdf", type=Path)
    parser.add_argument("--sim", choices=("both", "mujoco", "pybullet"), default="both")
    parser.add_argument("--max-penetration-mm", type=float, default=5.0)
    parser.add_argument("--min-reach", type=float, default=0.9)
    parser.add_argument("--seconds", type=float, default=2.0, help="simulated seconds each way")
    args = parser.parse_args(argv)
    with stdout_to_stderr() as real_stdout:
        urdf_path = args.urdf.resolve()
        try:
            read_urdf(urdf_path)
        except (OSError, ValueError, AttributeError) as e:
            print(f"check_contacts: cannot read {urdf_path}: {e}", file=sys.stderr)
            return 2
        report: dict = {"urdf": str(urdf_path)}
        failures: list[str] = []
        for sim in ("mujoco", "pybullet") if args.sim == "both" else (args.sim,):
            t0 = time.perf_counter()
            try:
                res = (check_mujoco if sim == "mujoco" else check_pybullet)(urdf_path, args)
            except ImportError as e:
                res = Result(sim)
                res.failures.append(f"not installed ({e}); run scripts/setup.sh")
            except Exception as e:  # a load failure or a checker bug: report, don't hide
                res = Result(sim)
                res.failures.append(f"{type(e).__name__}: {str(e).strip()}")
            report[sim] = res.as_json()
            report[sim]["total_s"] = round(time.perf_counter() - t0, 3)
            failures += [f"{sim}: {f}" for f in res.failures]
        return finish_report("check_contacts", report, failures, real_stdout)


if __name__ == "__main__":
    sys.exit(main())
