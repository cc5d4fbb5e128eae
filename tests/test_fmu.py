"""The FMI 3.0 co-simulation FMU of the slosh model (docs/fmu.md), through FMPy: schema validation,
simulation with tabulated tank motion against the rigid-body loads, the reported slosh frequency,
rollback with get/set/serialized FMU states, errors, and the quick form of ``fmu-fmpy-roundtrip``.

The FMU is built by ``scripts/build-fmu --debug`` (the dev-profile library that ``cargo test`` already
built in the same target directory, so CI pays only for packing it), or taken from ``$RAILSLOSH_FMU``.
"""

from __future__ import annotations

import math
import shutil
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from railslosh import fmu as rfmu
from railslosh import validate
from railslosh.constants import GRAVITY

fmpy = pytest.importorskip("fmpy", reason="FMPy is not installed (pip install '.[test]')")


@pytest.fixture(scope="module")
def fmu_file():
    try:
        return rfmu.find_fmu(debug=True)
    except rfmu.FmuUnavailable as exc:
        if shutil.which("cargo") is None:
            pytest.skip(f"cargo not found, cannot build the FMU: {exc}")
        raise


@pytest.fixture(scope="module")
def fmu_path(fmu_file):
    """The FMU extracted once (the dev-profile library is large); FMPy runs from the directory."""
    d = fmpy.extract(str(fmu_file))
    yield d
    shutil.rmtree(d, ignore_errors=True)


def test_fmpy_validates_the_fmu(fmu_file):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmu_file)) == []
    md = fmpy.read_model_description(str(fmu_file))
    assert md.fmiVersion == "3.0"
    assert md.coSimulation.modelIdentifier == "railslosh_slosh"
    with zipfile.ZipFile(fmu_file) as z:
        cs = ET.fromstring(z.read("modelDescription.xml")).find("CoSimulation")
        assert "binaries/x86_64-linux/railslosh_slosh.so" in z.namelist()
    assert cs.get("canGetAndSetFMUState") == "true" and cs.get("canSerializeFMUState") == "true"
    names = {v.name: v for v in md.modelVariables}
    assert all(names[n].causality == "input" for n in rfmu.INPUTS)
    assert all(names[n].causality == "output" for n in rfmu.OUTPUTS)
    assert sorted(o.variable.name for o in md.outputs) == sorted(rfmu.OUTPUTS)
    assert float(names["gravity_z"].start) == -GRAVITY


def test_steady_tabulated_acceleration_gives_rigid_body_loads(fmu_path):
    # a_x, a_y ramped in over 1 s then held; damped pendulum settles: F = m (g - a), M = com x F
    t = np.array([0.0, 1.0, 12.0])
    motion = rfmu.tank_motion(t, a_x=[0.0, -0.5, -0.5], a_y=[0.0, 3.0, 3.0])
    res = rfmu.simulate(fmu_path, 12.0, motion, {"damping_ratio": 0.25, "ref_z": 0.1})
    m = res["mass"][-1]
    L, a, b = rfmu.SWRI["length"], rfmu.SWRI["semi_axis_y"], rfmu.SWRI["semi_axis_z"]
    assert m == pytest.approx(1000.0 * 0.5 * math.pi * a * b * L, rel=1e-9)
    last = res[-1]
    assert last["F_x"] == pytest.approx(-m * -0.5, rel=1e-4)
    assert last["F_y"] == pytest.approx(-m * 3.0, rel=1e-4)
    assert last["F_z"] == pytest.approx(-m * rfmu.GRAVITY, rel=1e-4)
    # the liquid leans away from the acceleration: com moves to -y and +x
    assert last["com_y"] < -1e-3 and last["com_x"] > 1e-4
    f = np.array([last["F_x"], last["F_y"], last["F_z"]])
    r = np.array([last["com_x"], last["com_y"], last["com_z"] - 0.1])
    np.testing.assert_allclose([last["M_x"], last["M_y"], last["M_z"]], np.cross(r, f), atol=1e-4 * m)
    # at t = 0, before any acceleration: hydrostatic load
    assert res["F_z"][0] == pytest.approx(-m * rfmu.GRAVITY, rel=1e-12)
    assert abs(res["F_y"][0]) < 1e-9 * m


def test_tilted_gravity_input_gives_the_weight_along_it(fmu_path):
    # a tank rolled by 5 degrees at rest: gravity has a lateral component in tank axes
    phi = math.radians(5.0)
    gy, gz = -rfmu.GRAVITY * math.sin(phi), -rfmu.GRAVITY * math.cos(phi)
    t = np.array([0.0, 0.5, 12.0])
    motion = rfmu.tank_motion(t, gravity_y=[0.0, gy, gy], gravity_z=[-rfmu.GRAVITY, gz, gz])
    res = rfmu.simulate(fmu_path, 12.0, motion, {"damping_ratio": 0.25})
    m = res["mass"][-1]
    assert res["F_y"][-1] == pytest.approx(m * gy, rel=1e-4)
    assert res["F_z"][-1] == pytest.approx(m * gz, rel=1e-4)
    # the free surface stays horizontal: the liquid moves toward -y in tank axes
    assert res["com_y"][-1] < 0.0


def test_free_oscillation_at_the_reported_frequency(fmu_path):
    # a longitudinal pulse, undamped: F_x rings at f_longitudinal (FMPy steps 5 ms)
    t = np.array([0.0, 0.1, 0.1, 6.0])
    motion = rfmu.tank_motion(t, a_x=[0.5, 0.5, 0.0, 0.0])
    res = rfmu.simulate(fmu_path, 6.0, motion, {"damping_ratio": 0.0}, output_interval=0.005)
    keep = res["time"] > 0.2
    period = rfmu.dominant_period(res["time"][keep], res["F_x"][keep])
    assert 1.0 / period == pytest.approx(res["f_longitudinal"][-1], rel=0.01)


def test_rollback_is_exact(fmu_path):
    d = rfmu.rollback_difference(fmu_path, {"model": 0}, 0.3, 0.6, 0.01)
    assert d["moved"] > 0.0
    assert d["rollback"] == 0.0
    assert d["serialized"] == 0.0


def test_ancf_model_rollback_is_exact(fmu_path):
    params = {"model": 1, "n_length": 1, "n_width": 2, "n_height": 1}
    d = rfmu.rollback_difference(fmu_path, params, 0.02, 0.05, 0.01)
    assert d["rollback"] == 0.0 and d["serialized"] == 0.0
    assert d["bytes"] > 1000  # the ANCF state (coordinates, velocities, accelerations) is in it


def test_invalid_parameter_names_the_field(fmu_path):
    messages = []

    def log(env, status, category, message):
        messages.append(message.decode())

    md = fmpy.read_model_description(str(fmu_path))
    from fmpy.fmi3 import FMU3Slave

    slave = FMU3Slave(guid=md.guid, unzipDirectory=fmu_path, modelIdentifier="railslosh_slosh", instanceName="bad")
    slave.instantiate(logMessage=log)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    with pytest.raises(Exception, match="fmi3SetFloat64"):
        slave.setFloat64([vr["fill"]], [1.5])
    assert any("invalid `fill` = 1.5: expected [0.01, 0.97]" in m for m in messages), messages
    slave.reset()
    slave.enterInitializationMode(startTime=0.0)
    slave.exitInitializationMode()
    with pytest.raises(Exception, match="fmi3DoStep"):
        slave.doStep(currentCommunicationPoint=1.0, communicationStepSize=0.1)
    assert "differs from the FMU time 0" in messages[-1]
    slave.freeInstance()


def test_tank_motion_rejects_unknown_inputs():
    with pytest.raises(ValueError, match="invalid `a_q`"):
        rfmu.tank_motion([0.0, 1.0], a_q=[0.0, 1.0])
    with pytest.raises(ValueError, match="invalid `t`"):
        rfmu.tank_motion([1.0, 0.0], a_y=[0.0, 1.0])


def test_quick_validation_case_passes(fmu_file, monkeypatch):
    monkeypatch.setenv("RAILSLOSH_FMU", str(fmu_file))
    recs = validate.run([rfmu.CASE], quick=True)
    failed = [r for r in recs if not r["passed"]]
    assert len(recs) >= 10 and not failed, failed
