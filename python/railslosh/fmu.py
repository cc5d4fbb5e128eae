"""The FMI 3.0 co-simulation FMU of the slosh model (``docs/fmu.md``), driven with FMPy.

``find_fmu`` locates ``railslosh_slosh.fmu`` (``$RAILSLOSH_FMU``, or built from a source checkout by
``scripts/build-fmu``), ``tank_motion`` tabulates tank motion as an FMPy input signal, ``simulate``
runs the FMU, and ``case_fmu_roundtrip`` is the validation case ``fmu-fmpy-roundtrip``.

Variables (all in the tank frame, SI units; loads are those of the fluid on the tank):

- inputs ``a_x..z`` (tank origin acceleration without gravity), ``omega_x..z``, ``omega_dot_x..z``,
  ``gravity_x..z`` (default (0, 0, -g0), g0 = 9.80665);
- outputs ``F_x..z``, ``M_x..z`` (about ``ref_x..z``), ``com_x..z``;
- parameters ``model`` (0 pendulum, 1 ANCF), ``fill``, ``density``, ``viscosity``, ``length``,
  ``semi_axis_y``, ``semi_axis_z``, ``ref_x..z``, ``h_max``, ``damping_ratio``, ``n_length``,
  ``n_width``, ``n_height``; calculated ``mass``, ``f_longitudinal``, ``f_lateral``.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from railslosh.constants import GRAVITY
from railslosh.records import CaseSkipped, Record, within

INPUTS = tuple(f"{g}_{c}" for g in ("a", "omega", "omega_dot", "gravity") for c in "xyz")
OUTPUTS = tuple(f"{g}_{c}" for g in ("F", "M", "com") for c in "xyz")
# default tank of the FMU: the SwRI elliptical tank of seed 003, half full of water
SWRI = {"length": 0.324, "semi_axis_y": 0.208585, "semi_axis_z": 0.132131}


class FmuUnavailable(RuntimeError):
    """No FMU could be found or built (no source checkout, or no cargo)."""


def source_root() -> Path | None:
    """The repository checkout this package runs from (it has ``scripts/build-fmu``), or None."""
    for start in (Path(__file__).resolve().parent, Path.cwd().resolve()):
        for d in (start, *start.parents):
            if (d / "scripts" / "build-fmu").is_file() and (d / "crates" / "railslosh-fmu").is_dir():
                return d
    return None


def find_fmu(build: bool = True, debug: bool = False) -> Path:
    """Path of ``railslosh_slosh.fmu``.

    ``$RAILSLOSH_FMU`` when set; otherwise, in a source checkout, ``dist/railslosh_slosh.fmu`` built
    (or brought up to date) by ``scripts/build-fmu`` when ``build`` and cargo is available
    (``debug``: the dev profile, whose build ``cargo test`` already made, packed as
    ``dist/railslosh_slosh-debug.fmu``). Without cargo, an FMU already in ``dist/`` is used (with
    ``debug``, the release one too). Raises :class:`FmuUnavailable` when there is none.
    """
    env = os.environ.get("RAILSLOSH_FMU")
    if env:
        p = Path(env)
        if not p.is_file():
            raise ValueError(f"invalid `RAILSLOSH_FMU` = {env!r}: expected the path of an existing .fmu file")
        return p
    root = source_root()
    if root is None:
        raise FmuUnavailable("no FMU: set RAILSLOSH_FMU, or run from a source checkout with cargo")
    names = ["railslosh_slosh-debug.fmu", "railslosh_slosh.fmu"] if debug else ["railslosh_slosh.fmu"]
    dist = root / "dist" / names[0]
    if build and shutil.which("cargo") is not None:
        cmd = ["bash", str(root / "scripts" / "build-fmu"), "--out", str(dist)] + (["--debug"] if debug else [])
        done = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"scripts/build-fmu failed:\n{done.stderr[-4000:]}")
        return dist
    for name in names:
        if (root / "dist" / name).is_file():
            return root / "dist" / name
    raise FmuUnavailable("no FMU: cargo not found and no dist/railslosh_slosh.fmu (run scripts/build-fmu)")


def tank_motion(t, **columns) -> np.ndarray:
    """Tabulated tank motion as an FMPy input signal: a structured array with ``time`` and every
    input, the given ones at the times ``t`` (FMPy interpolates linearly between rows), the others
    at their defaults (zero; ``gravity_z`` = -g0)."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 1 or np.any(np.diff(t) < 0) or not np.all(np.isfinite(t)):
        raise ValueError("invalid `t`: expected a non-decreasing 1-D array of finite times")
    unknown = sorted(set(columns) - set(INPUTS))
    if unknown:
        raise ValueError(f"invalid `{unknown[0]}`: expected inputs {', '.join(INPUTS)}")
    sig = np.zeros(t.size, dtype=[("time", float)] + [(k, float) for k in INPUTS])
    sig["time"] = t
    sig["gravity_z"] = -GRAVITY
    for k, v in columns.items():
        v = np.broadcast_to(np.asarray(v, dtype=float), t.shape)
        if not np.all(np.isfinite(v)):
            raise ValueError(f"invalid `{k}`: expected finite values")
        sig[k] = v
    return sig


def simulate(
    fmu: str | Path,
    t_end: float,
    motion: np.ndarray | None = None,
    parameters: dict[str, float] | None = None,
    output_interval: float = 0.01,
    outputs: tuple[str, ...] = OUTPUTS + ("mass", "f_lateral", "f_longitudinal"),
) -> np.ndarray:
    """Run the FMU (the .fmu file or its extracted directory) with FMPy from 0 to ``t_end`` with
    communication step ``output_interval``; returns FMPy's structured result (``time`` and the
    ``outputs``)."""
    from fmpy import simulate_fmu

    return simulate_fmu(
        str(fmu),
        stop_time=t_end,
        output_interval=output_interval,
        input=motion,
        start_values=dict(parameters or {}),
        output=list(outputs),
        fmi_type="CoSimulation",
    )


class Instance:
    """A low-level FMPy instance of the FMU (for rollback): parameters, inputs, steps, outputs.
    ``fmu`` is the .fmu file or the directory it was extracted to."""

    def __init__(self, fmu: str | Path, parameters: dict[str, float] | None = None):
        from fmpy import extract, read_model_description
        from fmpy.fmi3 import FMU3Slave

        self.md = read_model_description(str(fmu))
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.extracted = not Path(fmu).is_dir()
        self.dir = extract(str(fmu)) if self.extracted else str(fmu)
        self.fmu = FMU3Slave(
            guid=self.md.guid,
            unzipDirectory=self.dir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName="railslosh",
        )
        self.fmu.instantiate()
        for k, v in (parameters or {}).items():
            self.set(k, v)
        self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.exitInitializationMode()
        self.t = 0.0

    def set(self, name: str, value: float) -> None:
        var = self.vars[name]
        if var.type == "Int32":
            self.fmu.setInt32([var.valueReference], [int(value)])
        else:
            self.fmu.setFloat64([var.valueReference], [float(value)])

    def get(self, names=OUTPUTS) -> np.ndarray:
        return np.array(self.fmu.getFloat64([self.vars[n].valueReference for n in names]))

    def run(self, t_end: float, h: float) -> None:
        n = round((t_end - self.t) / h)
        for k in range(n):
            t_next = self.t + h if k < n - 1 else t_end
            self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=t_next - self.t)
            self.t = t_next

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()
        if self.extracted:
            shutil.rmtree(self.dir, ignore_errors=True)


def rollback_difference(fmu: str | Path, parameters: dict[str, float], t_save: float, t_end: float, h: float) -> dict:
    """Largest |output difference| between a run from ``t_save`` to ``t_end`` and its repetition after
    rolling back (fmi3SetFMUState), and after a serialize/deserialize round trip of the saved state."""
    inst = Instance(fmu, parameters)
    try:
        inst.set("a_y", 2.0)
        inst.set("omega_z", 0.1)
        inst.run(t_save, h)
        state = inst.fmu.getFMUState()
        inst.run(t_end, h)
        first = inst.get()
        inst.set("a_y", -3.0)  # a different input after the saved point must not leak into the rerun
        inst.run(t_end + 5 * h, h)
        inst.fmu.setFMUState(state)
        inst.t = t_save
        inst.run(t_end, h)
        again = inst.get()
        blob = inst.fmu.serializeFMUState(state)
        inst.fmu.freeFMUState(state)
        restored = inst.fmu.deserializeFMUState(blob)
        inst.fmu.setFMUState(restored)
        inst.t = t_save
        inst.run(t_end, h)
        deserialized = inst.get()
        inst.fmu.freeFMUState(restored)
        return {
            "rollback": float(np.max(np.abs(again - first))),
            "serialized": float(np.max(np.abs(deserialized - first))),
            "moved": float(np.max(np.abs(first))),
            "bytes": len(blob),
        }
    finally:
        inst.close()


def dominant_period(t: np.ndarray, x: np.ndarray) -> float:
    """Mean period of x(t) from its upward zero crossings (linear interpolation)."""
    up = np.nonzero((x[:-1] <= 0.0) & (x[1:] > 0.0))[0]
    if up.size < 3:
        return math.nan
    tc = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    return float((tc[-1] - tc[0]) / (tc.size - 1))


CASE = "fmu-fmpy-roundtrip"
CASE_DESCRIPTION = (
    "FMI 3.0 co-simulation FMU of the slosh model: FMPy validates it and simulates it with tabulated tank motion "
    "(steady lateral acceleration: F = m (g - a); free oscillation at the reported slosh frequency); get/set/serialize "
    "FMU state rolls back exactly (pendulum and ANCF models); full form: ANCF loads under steady acceleration"
)


def case_fmu_roundtrip(quick: bool) -> list[Record]:
    """The validation case ``fmu-fmpy-roundtrip`` (skipped without FMPy or an FMU)."""
    try:
        from fmpy.validation import validate_fmu
    except ImportError as exc:
        raise CaseSkipped(f"{CASE}: skipped: FMPy is not installed (pip install fmpy)") from exc
    try:
        # quick: the dev-profile library that `cargo test` built; full: release (the ANCF run)
        fmu = find_fmu(debug=quick)
    except FmuUnavailable as exc:
        raise CaseSkipped(f"{CASE}: skipped: {exc}") from exc
    from fmpy import extract

    problems = validate_fmu(str(fmu))
    unzipped = extract(str(fmu))  # once: every run below starts from the directory
    try:
        return roundtrip_records(unzipped, problems, quick)
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)


def roundtrip_records(fmu: str | Path, problems: list[str], quick: bool) -> list[Record]:
    """Records of ``fmu-fmpy-roundtrip`` for an FMU (file or extracted directory) and its FMPy
    validation problems."""
    c = CASE
    recs = [within(c, "FMPy validate_fmu problems", len(problems), 0, 0)]
    rho, (L, a, b) = 1000.0, (SWRI["length"], SWRI["semi_axis_y"], SWRI["semi_axis_z"])
    m_ref = rho * 0.5 * math.pi * a * b * L

    # steady lateral + vertical acceleration, ramped in over 0.5 s (pendulum, damped)
    ay, az = 2.0, 1.0
    t = np.array([0.0, 0.5, 10.0])
    res = simulate(fmu, 10.0, tank_motion(t, a_y=[0.0, ay, ay], a_z=[0.0, az, az]), {"damping_ratio": 0.2})
    m = float(res["mass"][-1])
    recs.append(within(c, "pendulum mass / (rho pi a b L / 2)", m / m_ref, 1.0, 1e-9))
    recs.append(within(c, "steady F_y / (-m a_y)", res["F_y"][-1] / (-m * ay), 1.0, 1e-3))
    recs.append(within(c, "steady F_z / (-m (g + a_z))", res["F_z"][-1] / (-m * (GRAVITY + az)), 1.0, 1e-3))
    recs.append(within(c, "steady F_x / (m g)", res["F_x"][-1] / (m * GRAVITY), 0.0, 1e-6))
    mx = res["com_y"][-1] * res["F_z"][-1] - res["com_z"][-1] * res["F_y"][-1]
    recs.append(within(c, "steady M_x / (com x F)_x", res["M_x"][-1] / mx, 1.0, 1e-3))

    # free lateral oscillation after a short pulse, undamped: period from the reported f_lateral
    t = np.array([0.0, 0.1, 0.1, 12.0])
    res = simulate(fmu, 12.0, tank_motion(t, a_y=[0.5, 0.5, 0.0, 0.0]), {"damping_ratio": 0.0}, output_interval=0.005)
    keep = res["time"] > 0.2
    period = dominant_period(res["time"][keep], res["F_y"][keep])
    recs.append(within(c, "free oscillation f / f_lateral", 1.0 / period / res["f_lateral"][-1], 1.0, 0.01))

    # rollback: identical outputs after fmi3SetFMUState and after serialize/deserialize
    for model, params, t_save, t_end, h in [
        ("pendulum", {"model": 0}, 0.3, 0.6, 0.01),
        ("ANCF", {"model": 1, "n_length": 1, "n_width": 2, "n_height": 1}, 0.02, 0.06, 0.01),
    ]:
        d = rollback_difference(fmu, params, t_save, t_end, h)
        recs.append(within(c, f"{model} rollback max |output difference|", d["rollback"], 0.0, 0.0))
        recs.append(within(c, f"{model} deserialized-state max |output difference|", d["serialized"], 0.0, 0.0))

    if not quick:
        # ANCF water under a steady lateral acceleration: mean loads over the last second vs m (g - a)
        ay = 1.0
        t = np.array([0.0, 0.3, 3.0])
        params = {"model": 1, "viscosity": 0.05, "n_length": 2, "n_width": 4, "n_height": 2}
        res = simulate(fmu, 3.0, tank_motion(t, a_y=[0.0, ay, ay]), params, output_interval=0.02)
        m = float(res["mass"][-1])
        late = res["time"] >= 2.0
        recs.append(within(c, "ANCF mass / (rho pi a b L / 2)", m / m_ref, 1.0, 0.01))
        recs.append(
            within(c, "ANCF mean F_y / (-m a_y), t in [2, 3] s", np.mean(res["F_y"][late]) / (-m * ay), 1.0, 0.1)
        )
        recs.append(
            within(c, "ANCF mean F_z / (-m g), t in [2, 3] s", np.mean(res["F_z"][late]) / (-m * GRAVITY), 1.0, 0.02)
        )
    return recs


FMU_CASES = {CASE: (CASE_DESCRIPTION, case_fmu_roundtrip)}
