"""Running a scene: the slosh run of a :class:`SloshScene`, or the vehicle run of the fluid model
:func:`railslosh.fluid_model.decide` picks for a :class:`Scene`."""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from railslosh import fluid_model, slosh, vehicle
from railslosh.scene.load import load_scene
from railslosh.scene.slosh import SloshScene
from railslosh.scene.vehicle import Scene


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
    :meth:`Scene.largest_step`).
    ``checkpoint`` keeps the run's whole state in that file every ``checkpoint_every`` recorded
    samples; ``resume_from`` continues the same scene from such a file, its results starting at the
    checkpoint (bit for bit those of the uninterrupted run; :func:`railslosh.vehicle.run`,
    :func:`railslosh.slosh.run`).
    Raises :class:`railslosh.slosh.SimulationError` when the run stops early."""
    sc = scene if isinstance(scene, Scene | SloshScene) else load_scene(scene)
    files = {"checkpoint": checkpoint, "checkpoint_every": checkpoint_every, "resume_from": resume_from}
    if isinstance(sc, SloshScene):
        args, kw = sc.run_args()
        res = slosh.run(*args, **kw, progress=progress, **files)
        res["scene"] = sc
        return res
    choice = fluid_model.decide(sc)
    step, step_reason = sc.largest_step(choice.model if sc.fluid is not None else "rigid")
    rows = np.asarray(sc.track_rows, dtype=float)
    try:
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
        exc.results.update(
            fluid_model=choice.model, fluid_model_reason=choice.reason, step=step, step_reason=step_reason
        )
        raise
    res |= {"fluid_model": choice.model, "fluid_model_reason": choice.reason, "step": step, "step_reason": step_reason}
    res["scene"] = sc
    return res
