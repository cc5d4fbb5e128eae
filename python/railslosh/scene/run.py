"""Running a scene: the slosh run of a :class:`SloshScene`, or the vehicle run of the fluid model
:func:`railslosh.fluid_model.decide` picks for a :class:`Scene`."""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from railslosh import fluid_model, slosh, vehicle
from railslosh.constants import GRAVITY
from railslosh.scene.load import load_scene
from railslosh.scene.slosh import SloshScene
from railslosh.scene.vehicle import Scene

MIRROR_LOAD_LIMIT = 1e-4
"""Largest lateral liquid load, as a fraction of the liquid's weight, that a run with mirror-symmetric
inputs (:meth:`Scene.mirror_symmetric`) may show before its lateral channels are flagged as
discretization error (:func:`mirror_symmetry`): 1e-4 m g is 34 N for a tank of light crude, about
0.1 % of the surge's peak longitudinal load on the ECP scenes."""


def mirror_symmetry(res: Mapping[str, Any], sc: Scene | SloshScene) -> dict[str, Any] | None:
    """For a vehicle run with liquid cargo, or a slosh run, whose inputs are mirror-symmetric
    (:meth:`Scene.mirror_symmetric`, :meth:`SloshScene.mirror_symmetric`), how far its liquid's lateral
    load strays from the exact zero:
    ``worst_lateral_load`` (N, the largest over the cars and samples) at ``worst_time`` (s), as
    ``relative`` to the liquid's weight; ``limit`` (N, :data:`MIRROR_LOAD_LIMIT` of that weight); and
    ``lateral_valid_until``: the first sample time at which the load exceeds the limit, after which
    the run's lateral channels (liquid lateral load and centre of mass, left against right wheel
    loads) are discretization error, not physics (``docs/validation.md``, "The ECP scenes' lateral
    channels"), or ``None`` when it never does. ``None`` for other runs."""
    if not sc.mirror_symmetric():
        return None
    if isinstance(sc, SloshScene):  # one tank: force_tank (n, 3)
        if "force_tank" not in res:
            return None
        fy = np.abs(np.asarray(res["force_tank"], dtype=float)[:, 1])
        weight = sc.liquid_mass() * GRAVITY
    else:  # every car's tank: fluid_force_tank (n, cars, 3)
        if "fluid_force_tank" not in res or not res.get("fluid_mass"):
            return None
        fy = np.abs(np.asarray(res["fluid_force_tank"], dtype=float)[..., 1]).max(axis=1)
        weight = float(res["fluid_mass"]) * GRAVITY
    t = np.asarray(res["t"], dtype=float)
    limit = MIRROR_LOAD_LIMIT * weight
    k = int(np.argmax(fy)) if len(fy) else 0
    over = np.flatnonzero(fy > limit)
    return {
        "inputs": "mirror-symmetric",
        "worst_lateral_load": float(fy[k]) if len(fy) else 0.0,
        "worst_time": float(t[k]) if len(t) else 0.0,
        "relative": float(fy[k] / weight) if len(fy) else 0.0,
        "limit": limit,
        "lateral_valid_until": float(t[over[0]]) if len(over) else None,
    }


def run_scene(
    scene: Scene | SloshScene | str | os.PathLike[str] | Mapping[str, Any],
    progress: Any = None,
    *,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int = 50,
    resume_from: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """Runs a scene (a :class:`Scene` or :class:`SloshScene`, or anything :func:`load_scene` takes)
    with :func:`railslosh.vehicle.run`, :func:`railslosh.vehicle.run_fluid` or
    :func:`railslosh.slosh.run`; returns its dict of arrays with ``"scene"`` added.

    ``progress(t, t_end, steps, newton_iterations, rejected_steps)`` is called during the run (about
    every 0.5 s of wall time); if it raises, the run stops and the exception propagates.
    Vehicle scenes with liquid cargo run the fluid model of :func:`railslosh.fluid_model.decide`
    (``[fluid] slosh_model``); every vehicle result carries ``fluid_model`` and ``fluid_model_reason``,
    and the largest step the run took with the rule that chose it (``step``, ``step_reason``:
    :meth:`Scene.largest_step`). Every result carries ``mirror_symmetry`` (:func:`mirror_symmetry`:
    for liquid on mirror-symmetric inputs, vehicle or slosh, the largest lateral liquid load and when
    the lateral channels stop being trustworthy; otherwise ``None``).
    ``checkpoint`` keeps the run's whole state in that file every ``checkpoint_every`` recorded
    samples; ``resume_from`` continues the same scene from such a file, its results starting at the
    checkpoint (bit for bit those of the uninterrupted run; :func:`railslosh.vehicle.run`,
    :func:`railslosh.slosh.run`).
    Raises :class:`railslosh.slosh.SimulationError` when the run stops early."""
    sc = scene if isinstance(scene, Scene | SloshScene) else load_scene(scene)
    files = {"checkpoint": checkpoint, "checkpoint_every": checkpoint_every, "resume_from": resume_from}
    extra: dict[str, Any] = {}  # what a vehicle run adds to its results, also on a failed run
    if isinstance(sc, Scene):
        choice = fluid_model.decide(sc)
        step, step_reason = sc.largest_step(choice.model if sc.fluid is not None else "rigid")
        extra = {
            "fluid_model": choice.model,
            "fluid_model_reason": choice.reason,
            "step": step,
            "step_reason": step_reason,
        }
    try:
        if isinstance(sc, SloshScene):
            args, kw = sc.run_args()
            res = slosh.run(*args, **kw, progress=progress, **files)
        else:
            rows = np.asarray(sc.track_rows, dtype=float)
            if sc.fluid is None:
                res = vehicle.run(rows, **sc.run_kwargs(), progress=progress, **files)
            elif choice.model == "ancf":
                res = vehicle.run_fluid(rows, **sc.fluid_kwargs(), progress=progress, **files)
            elif choice.model == "pendulum":
                axis = choice.axis or "longitudinal"
                res = vehicle.run_equivalent(rows, **sc.equivalent_kwargs(axis), progress=progress, **files)
            else:
                res = vehicle.run(rows, **sc.rigid_kwargs(), progress=progress, **files)
    except slosh.SimulationError as exc:
        exc.results.update(extra)
        exc.results["mirror_symmetry"] = mirror_symmetry(exc.results, sc)
        raise
    res |= extra
    res["mirror_symmetry"] = mirror_symmetry(res, sc)
    res["scene"] = sc
    return res
