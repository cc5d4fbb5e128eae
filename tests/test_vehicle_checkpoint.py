"""A vehicle run checkpoints its whole state and resumes from it bit for bit (issue 18): rigid
lading, the equivalent model and the ANCF liquid, through the public Python API."""

import numpy as np
import pytest

from railslosh import vehicle
from railslosh.slosh import SimulationError

TRACK = [[0.0] * 6, [3000.0] + [0.0] * 5]
COMMON = {"station": 300.0, "speed": 10.0, "record_every": 0.02}


@pytest.mark.parametrize(
    ("run", "extra"),
    [
        (vehicle.run, {"lading_mass": 30_000.0, "lading_height": -0.3}),
        (vehicle.run_equivalent, {"fill": 0.5}),
        (vehicle.run_fluid, {"fill": 0.5, "counts": (2, 2, 2)}),
    ],
)
def test_a_run_resumed_from_its_checkpoint_continues_bit_for_bit(run, extra, tmp_path):
    ck = tmp_path / "run.ckpt"
    full = run(TRACK, **COMMON, **extra, t_end=0.3)
    # a shorter run writes checkpoints after samples 3 and 7 (t = 0.06 and 0.14 s), before its end
    run(TRACK, **COMMON, **extra, t_end=0.16, checkpoint=ck, checkpoint_every=4)
    resumed = run(TRACK, **COMMON, **extra, t_end=0.3, resume_from=ck)
    assert resumed["t"][0] == pytest.approx(0.14)
    k = len(full["t"]) - len(resumed["t"])
    assert k == 7
    names = [n for n, v in full.items() if isinstance(v, np.ndarray) and v.shape[:1] == full["t"].shape]
    assert {"wheel_vertical", "coupler_force", "l_over_v"} <= set(names)
    for name in names:
        assert np.array_equal(np.asarray(full[name])[k:], np.asarray(resumed[name]), equal_nan=True), name


def test_a_checkpoint_of_another_train_or_a_missing_file_is_refused(tmp_path):
    ck = tmp_path / "run.ckpt"
    vehicle.run(TRACK, **COMMON, t_end=0.1, checkpoint=ck, checkpoint_every=2)
    with pytest.raises(SimulationError, match="does not fit this train"):
        vehicle.run(TRACK, **COMMON, t_end=0.3, cars=2, resume_from=ck)
    with pytest.raises(SimulationError, match="cannot read checkpoint"):
        vehicle.run(TRACK, **COMMON, t_end=0.3, resume_from=tmp_path / "missing.ckpt")
    with pytest.raises(ValueError, match=r"invalid `checkpoint_every` = 0: expected an integer >= 1"):
        vehicle.run(TRACK, **COMMON, t_end=0.1, checkpoint=ck, checkpoint_every=0)
