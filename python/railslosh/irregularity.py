"""Track irregularities (issue 20 §1): the deviation of the rails from their design position, as
four channels of distance along the track, generated from a spectrum, read from a measured file
or built from isolated defects, and handed to the vehicle runs (:func:`railslosh.vehicle.run`,
``run_fluid``, ``run_equivalent``: ``irregularity=``).

    >>> from railslosh import irregularity, rail, vehicle
    >>> irr = irregularity.generate("fra", track_class=5, length=300.0, start=57.0, taper=5.0)
    >>> irr.rms()                                    # m, per channel
    >>> tangent = rail.Track([0, 1000], curvature=[0, 0], superelevation=[0, 0])
    >>> vehicle.wheelset_stations(cars=1, station=50.0)[0]     # the leading wheelset at t = 0, m
    55.4145
    >>> res = vehicle.run(tangent, station=50.0, speed=60 / 3.6, drive=True, t_end=2.0, lading_mass=36e3,
    ...                   irregularity=irr.with_channels(["vertical"]))
    >>> irregularity.write(irr, "fra5.csv", units="mm"); irregularity.read("fra5.csv") == irr
    True

**Channels and signs** (``docs/frames.md``, "Track irregularities"), metres, track frame: ``vertical``
(mean height of the two rails, up), ``alignment`` (mean lateral position, to the left),
``cross_level`` (right rail minus left rail height, the sign of super-elevation) and ``gauge``
(widening). The model, its spectra and the evaluation between samples (C¹ cubic Hermite, end values
held outside the grid) are ``rail_mbs::track::irregularity``; this module wraps them.

**Spectra** (:data:`SPECTRA`): the US FRA track classes 1 (worst) to 6 (``kind = "fra"`` with
``track_class``) and the ERRI B176 low- and high-level spectra (``"erri_low"``, ``"erri_high"``; no
gauge spectrum: the gauge stays zero). :func:`psd` is the one-sided target S(Ω) in m² per rad/m at
spatial angular frequencies Ω = 2π/λ (rad/m); :func:`welch_psd` estimates the same quantity from
samples; :func:`band_ratios` compares the two in one-third-octave bands (``railslosh validate
track-irregularity``).

**The train starts on perfect track.** The value held before the first sample lies under every
wheel behind it, so an irregularity must be zero under the train at t = 0 (else the wheels start
penetrating the rails or in the air: a violent start). The vehicle runs refuse one that is not
zero up to :data:`CLEARANCE` ahead of the leading wheelset; start the irregular section (and its
taper, which brings a generated track in from zero) ahead of it.

**File format** (:func:`read`, :func:`write`): UTF-8 text, comma separated.

* Comment lines start with ``#`` (anywhere; blank lines are skipped too). One comment line must
  say the units of the four channels, ``# units: mm`` or ``# units: m`` (or the reader is given
  ``units``). Optional ``# start: <m>`` and ``# step: <m>`` give the grid exactly (written by
  :func:`write`; the distance column must agree with them). Other comment lines are free text
  (:func:`write` puts the irregularity's :attr:`Irregularity.spec` in one).
* The first other line is the header: the five column names ``distance, vertical, alignment,
  cross_level, gauge`` in any order, each once, no others.
* Then one row per sample, at least 2: the distance along the track in **metres** (always), and
  the four channels in the file's units. Distances increase uniformly: each within 0.1 % of the
  spacing of ``start + k step`` (without a ``# step:`` line the spacing is (last − first)/(rows − 1)).

Errors say which line and column, in the one form ``invalid `file` = '<path>': expected …``.
:func:`write` writes every value with the fewest digits that read back to the same double
(``repr``); in millimetres it shifts that decimal text by three places instead of multiplying, and
:func:`read` reads decimal text and divides by 1000 exactly before rounding once to a double, so
a write → read round trip is exact, bit for bit, in both units.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import numbers
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any

import numpy as np

from railslosh import _core
from railslosh.constants import INCH
from railslosh.limits import invalid, suggest, unknown

__all__ = [
    "CHANNELS",
    "CLEARANCE",
    "DEFECTS",
    "FRA_CROSS_LEVEL_LIMITS",
    "FRA_GAUGE_LIMITS",
    "MAX_SAMPLES",
    "MEANINGS",
    "PSD_TOLERANCE",
    "SPECTRA",
    "UNIFORM_TOLERANCE",
    "UNITS",
    "WELCH_NPERSEG",
    "Irregularity",
    "band_ratios",
    "class_limit_exceedances",
    "file_sha256",
    "from_spec",
    "generate",
    "psd",
    "read",
    "third_octave_bands",
    "welch_psd",
    "with_defects",
    "write",
]

CHANNELS = ("vertical", "alignment", "cross_level", "gauge")
"""The four channels, in storage order (``rail_mbs::track::Channel``)."""
MEANINGS: dict[str, tuple[str, str]] = {
    "vertical": ("vertical profile: mean height of the two rails", "positive up"),
    "alignment": ("alignment: mean lateral position of the two rails", "positive to the left"),
    "cross_level": ("cross-level: height of the right rail minus the left rail", "positive: right rail higher"),
    "gauge": ("gauge widening", "positive wider"),
}
"""Each channel in words and its sign (``docs/frames.md``, "Track irregularities")."""
SPECTRA = ("fra", "erri_low", "erri_high")
"""Spectra of :func:`generate`: FRA track classes 1–6 (with ``track_class``), ERRI B176 low and high."""
DEFECTS: dict[str, tuple[str, ...]] = {
    "cosine_dip": ("start", "length", "depth"),
    "cusp": ("at", "length", "depth"),
    "twist": ("start", "base", "cross_level", "hold"),
}
"""The isolated defects of :func:`with_defects` and their keys (metres; ``hold`` defaults to 0)."""
UNITS = ("mm", "m")
"""Channel units of an irregularity file."""
CLEARANCE = 1.0
"""m: how far ahead of the leading wheelset at t = 0 the track must still be perfect."""
UNIFORM_TOLERANCE = 1e-3
"""Largest deviation of a file's distances from the uniform grid, as a fraction of the spacing."""
MAX_SAMPLES = 2_000_000
"""Most samples per channel of a generated or perfect track (``length / step``; 500 km at 0.25 m)."""
WELCH_NPERSEG = 1024
"""Default samples per Welch segment of :func:`welch_psd` (256 m at the 0.25 m default spacing)."""

FRA_GAUGE_LIMITS: dict[int, tuple[float, float]] = {
    1: (-0.5 * INCH, 1.5 * INCH),
    2: (-0.5 * INCH, 1.25 * INCH),
    3: (-0.5 * INCH, 1.25 * INCH),
    4: (-0.5 * INCH, 1.0 * INCH),
    5: (-0.5 * INCH, 1.0 * INCH),
}
"""FRA Track Safety Standards, 49 CFR 213.53: the gauge of class 1–5 track is at least 4 ft 8 in and
at most 4 ft 10 in (class 1), 4 ft 9 3/4 in (2 and 3), 4 ft 9 1/2 in (4 and 5); here as the
``gauge`` channel's range about the nominal 4 ft 8 1/2 in (m). Class 6 (Subpart G) is not listed."""
FRA_CROSS_LEVEL_LIMITS: dict[int, float] = {1: 3.0 * INCH, 2: 2.0 * INCH, 3: 1.75 * INCH, 4: 1.25 * INCH, 5: 1.0 * INCH}
"""49 CFR 213.63: the largest deviation from zero cross-level on tangent track of class 1–5 (m)."""

_COLUMNS = ("distance", *CHANNELS)
_SCALE = {"m": 0, "mm": 3}  # decimal places a value in these units is shifted by from metres


def _real(name: str, value: Any, what: str = "a number (m)") -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise invalid(name, value, what)
    return float(value)


def _unknown_channel(name: str, value: Any) -> ValueError:
    close = suggest(value, CHANNELS) if isinstance(value, str) else None
    hint = f" (did you mean {close!r}?)" if close else ""
    return invalid(name, value, f"one of {', '.join(CHANNELS)}{hint}")


def _channel_names(channels: Any, name: str = "channels") -> list[str]:
    if isinstance(channels, str) or not isinstance(channels, Iterable):
        raise invalid(name, channels, f"a list of channel names from {', '.join(CHANNELS)}")
    out = list(channels)
    for i, c in enumerate(out):
        if not isinstance(c, str) or c not in CHANNELS:
            raise _unknown_channel(f"{name}[{i}]", c)
    if len(set(out)) != len(out):
        raise invalid(name, out, "each channel at most once")
    return out


@dataclass(frozen=True, eq=False)
class Irregularity:
    """Track irregularity samples on the uniform grid ``start + k step`` (m): one array per
    channel (m, read-only), and ``spec``, where it came from (``kind`` ``"fra"``, ``"erri_low"``,
    ``"erri_high"``, ``"file"``, ``"perfect"`` or ``"samples"`` and its parameters; a dict that
    :func:`from_spec` rebuilds it from). Equality (``==``) is bitwise on the grid and the samples."""

    start: float
    step: float
    vertical: np.ndarray
    alignment: np.ndarray
    cross_level: np.ndarray
    gauge: np.ndarray
    spec: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        start = _real("start", self.start)
        step = _real("step", self.step)
        if not math.isfinite(start):
            raise invalid("start", self.start, "a finite distance (m)")
        if not (math.isfinite(step) and step > 0):
            raise invalid("step", self.step, "a sample spacing > 0 m")
        arrays = []
        for c in CHANNELS:
            try:
                x = np.array(getattr(self, c), dtype=np.float64)
            except (TypeError, ValueError) as exc:
                raise invalid(c, getattr(self, c), "a 1-D array of numbers (m)") from exc
            if x.ndim != 1:
                raise invalid(c, f"an array of shape {x.shape}", "a 1-D array of numbers (m)")
            arrays.append(x)
        n = len(arrays[0])
        if n < 2:
            raise invalid("vertical", f"{n} samples", "at least 2 samples per channel")
        for c, x in zip(CHANNELS, arrays, strict=True):
            if len(x) != n:
                raise invalid(c, f"{len(x)} samples", f"{n} samples, as many as the others")
            bad = np.flatnonzero(~np.isfinite(x))
            if bad.size:
                raise invalid(c, f"{x[bad[0]]} at sample {bad[0]}", "finite values (m)")
            x.flags.writeable = False
            object.__setattr__(self, c, x)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "step", step)
        object.__setattr__(self, "spec", dict(self.spec))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Irregularity):
            return NotImplemented
        return (
            self.start == other.start
            and self.step == other.step
            and all(np.array_equal(getattr(self, c), getattr(other, c)) for c in CHANNELS)
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def samples(self) -> int:
        """Number of samples per channel."""
        return len(self.vertical)

    @property
    def distance(self) -> np.ndarray:
        """Distance of each sample along the track, m: ``start + k step``."""
        return self.start + self.step * np.arange(self.samples, dtype=np.float64)

    @property
    def end(self) -> float:
        """Distance of the last sample, m."""
        return self.start + self.step * (self.samples - 1)

    def channel(self, name: str) -> np.ndarray:
        """The samples of channel ``name`` (m)."""
        if not isinstance(name, str) or name not in CHANNELS:
            raise _unknown_channel("channel", name)
        return getattr(self, name)

    def to_dict(self) -> dict[str, Any]:
        """The samples dict of the compiled kernels (``railslosh._core``): ``start``, ``step`` and
        one array per channel."""
        return {"start": self.start, "step": self.step, **{c: getattr(self, c) for c in CHANNELS}}

    @classmethod
    def from_dict(cls, samples: Mapping[str, Any], spec: Mapping[str, Any] | None = None) -> Irregularity:
        """From a samples dict (``start``, ``step``, the four channels), e.g. of
        ``railslosh._core.track_irregularity``; ``spec`` defaults to ``{"kind": "samples"}``."""
        if not isinstance(samples, Mapping):
            raise invalid("irregularity", samples, "an Irregularity or a samples dict (start, step, and the channels)")
        for k in ("start", "step", *CHANNELS):
            if k not in samples:
                raise invalid("irregularity", f"a dict without {k!r}", "the keys start, step, " + ", ".join(CHANNELS))
        return cls(
            samples["start"],
            samples["step"],
            *(samples[c] for c in CHANNELS),
            spec=dict(spec) if spec is not None else {"kind": "samples"},
        )

    def rms(self) -> dict[str, float]:
        """Root-mean-square of each channel's samples, m."""
        return {c: float(np.sqrt(np.mean(np.square(getattr(self, c))))) for c in CHANNELS}

    def summary(self) -> dict[str, Any]:
        """:attr:`spec` with the grid (``first``, ``last`` distance, ``step``, ``samples``) and the
        ``rms`` of each channel (m): what a run records (``run.json``, results attributes)."""
        return {
            **self.spec,
            "first": self.start,
            "last": self.end,
            "step": self.step,
            "samples": self.samples,
            "rms": self.rms(),
            **({"class_limits": limits} if (limits := self.class_limits()) else {}),
        }

    def class_limits(self, until: float | None = None) -> dict[str, dict[str, Any]]:
        """For a generated FRA track of class 1–5 (``spec`` ``kind = "fra"``), its ``gauge`` and
        ``cross_level`` extremes (over the samples up to distance ``until``, m; default all)
        against the class's limits (:data:`FRA_GAUGE_LIMITS`, :data:`FRA_CROSS_LEVEL_LIMITS`; m):
        ``{channel: {"min", "max", "limits", "within"}}``; empty for other tracks. The Gaussian
        realization of a class's spectrum is not bounded: it can exceed the limits that define the
        class."""
        track_class = self.spec.get("class")
        if self.spec.get("kind") != "fra" or track_class not in FRA_GAUGE_LIMITS:
            return {}
        n = (
            self.samples
            if until is None
            else int(np.clip(np.floor((until - self.start) / self.step) + 1, 1, self.samples))
        )
        cross = FRA_CROSS_LEVEL_LIMITS[track_class]
        out: dict[str, dict[str, Any]] = {}
        for channel, (lo, hi) in (("gauge", FRA_GAUGE_LIMITS[track_class]), ("cross_level", (-cross, cross))):
            x = getattr(self, channel)[:n]
            xmin, xmax = float(x.min()), float(x.max())
            out[channel] = {"min": xmin, "max": xmax, "limits": [lo, hi], "within": lo <= xmin and xmax <= hi}
        return out

    def with_channels(self, channels: Iterable[str]) -> Irregularity:
        """The same irregularity with only ``channels`` kept (the others zero); ``spec`` says which."""
        keep = _channel_names(channels)
        arrays = {c: getattr(self, c) if c in keep else np.zeros(self.samples) for c in CHANNELS}
        return dataclasses.replace(self, **arrays, spec={**self.spec, "channels": keep})

    def placed(self, start: float) -> Irregularity:
        """The same samples with the first at distance ``start`` (m); ``spec`` records it."""
        start = _real("start", start)
        return dataclasses.replace(self, start=start, spec={**self.spec, "start": start})

    def clear_until(self) -> float:
        """The distance up to which every channel is exactly zero, m (the track is perfect before
        it; ``-inf`` when the value held before the first sample is not zero). The interpolation
        between samples (cubic Hermite with centred slopes) reaches two spacings back from the
        first non-zero sample."""
        x = np.vstack([getattr(self, c) for c in CHANNELS])
        nonzero = np.flatnonzero(np.any(x != 0.0, axis=0))
        if nonzero.size == 0:
            return math.inf
        if nonzero[0] == 0:
            return -math.inf
        return self.start + self.step * (nonzero[0] - 2) if nonzero[0] >= 2 else self.start


# --- generation, defects, specs ---------------------------------------------------------------------


def class_limit_exceedances(irr: Irregularity, until: float | None = None) -> list[str]:
    """The FRA class limits a generated track exceeds up to distance ``until`` (m; default its end;
    :meth:`Irregularity.class_limits`), each in words; empty when it keeps them (or is no FRA class
    1–5 track)."""
    out = []
    for channel, c in irr.class_limits(until).items():
        if not c["within"]:
            lo, hi = c["limits"]
            out.append(
                f"{channel} {1e3 * c['min']:+.1f} to {1e3 * c['max']:+.1f} mm against "
                f"{1e3 * lo:+.1f} to {1e3 * hi:+.1f} mm ({'49 CFR 213.53' if channel == 'gauge' else '49 CFR 213.63'})"
            )
    return out


def _rename(exc: ValueError, names: Mapping[str, str]) -> ValueError:
    msg = str(exc)
    for old, new in names.items():
        if msg.startswith(f"invalid `{old}`"):
            return ValueError(f"invalid `{new}`" + msg[len(f"invalid `{old}`") :])
    return exc


def _check_kind(kind: Any) -> str:
    if not isinstance(kind, str) or kind not in SPECTRA:
        raise invalid("kind", kind, f"a spectrum, one of {', '.join(repr(s) for s in SPECTRA)}")
    return kind


def _check_class(track_class: Any) -> int | None:
    if track_class is None:
        return None
    if isinstance(track_class, bool) or not isinstance(track_class, numbers.Integral) or not 1 <= int(track_class) <= 6:
        raise invalid("track_class", track_class, "an FRA track class 1–6")
    return int(track_class)


def _check_samples(length: float, step: float, name: str = "length") -> None:
    """Refuses grids of more than :data:`MAX_SAMPLES` samples (the kernels would try to allocate them)."""
    if math.isfinite(length) and math.isfinite(step) and step > 0 and length / step > MAX_SAMPLES:
        raise invalid(name, length, f"at most {MAX_SAMPLES} samples: ≤ {MAX_SAMPLES * step:.6g} m at step = {step:g} m")


def generate(
    kind: str = "fra",
    track_class: int | None = None,
    *,
    length: float = 1000.0,
    start: float = 0.0,
    step: float = 0.25,
    wavelengths: tuple[float, float] = (1.0, 70.0),
    seed: int = 1,
    taper: float = 20.0,
    channels: Sequence[str] | None = None,
) -> Irregularity:
    """Draws an irregularity from a spectrum (``rail_mbs::track::Irregularity::generate``): ``kind``
    ``"fra"`` (with ``track_class`` 1–6), ``"erri_low"`` or ``"erri_high"``; ``length`` m of track
    from ``start`` sampled every ``step`` m (at most half the shortest wavelength); the wavelengths
    from ``wavelengths[0]`` to ``wavelengths[1]`` m (the longest at most ``length``) as a sum of
    cosines Ω_k = 2πk/length with random phases from ``seed`` (0 to 2⁶⁴ − 1; the same seed gives
    the same track bit for bit, each channel its own phases); a raised-cosine ``taper`` (m) from
    zero at ``start``; ``channels`` the names to draw (default all four; the others stay zero and
    the drawn ones do not change). The cost grows with length²: about 2 s for 4 km on one core."""
    kind = _check_kind(kind)
    cls = _check_class(track_class)
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= int(seed) < 2**64:
        raise invalid("seed", seed, "an integer from 0 to 2^64 - 1")
    if not isinstance(wavelengths, Sequence) or isinstance(wavelengths, str) or len(wavelengths) != 2:
        raise invalid("wavelengths", wavelengths, "(shortest, longest) wavelength, m")
    wl = (_real("wavelengths[0]", wavelengths[0]), _real("wavelengths[1]", wavelengths[1]))
    names = list(CHANNELS) if channels is None else _channel_names(channels)
    args = {k: _real(k, v) for k, v in (("length", length), ("start", start), ("step", step), ("taper", taper))}
    _check_samples(args["length"], args["step"])
    try:
        d = _core.track_irregularity(
            kind, args["length"], track_class=cls, wavelengths=wl, seed=int(seed), channels=names,
            start=args["start"], step=args["step"], taper=args["taper"],
        )  # fmt: skip
    except ValueError as exc:
        raise _rename(exc, {"class": "track_class"}) from exc
    spec = {
        "kind": kind,
        **({"class": cls} if cls is not None else {}),
        "seed": int(seed),
        "wavelengths": list(wl),
        "taper": args["taper"],
        "start": args["start"],
        "length": args["length"],
        "step": args["step"],
        "channels": names,
    }
    return Irregularity.from_dict(d, spec)


def _defect(d: Any, i: int) -> dict[str, Any]:
    """One defect dict, checked: its ``type`` and keys, numbers."""
    name = f"defects[{i}]"
    if not isinstance(d, Mapping):
        raise invalid(name, d, f"a table with a `type` ({', '.join(DEFECTS)}) and its keys")
    kind = d.get("type")
    if not isinstance(kind, str) or kind not in DEFECTS:
        raise invalid(f"{name}.type", kind, f"one of {', '.join(repr(k) for k in DEFECTS)}")
    keys = DEFECTS[kind]
    out: dict[str, Any] = {"type": kind}
    for k, v in d.items():
        if k == "type":
            continue
        if k not in keys:
            raise unknown(f"{name}.{k}", f"key of a {kind} defect", keys, prefix=f"{name}.")
        out[k] = _real(f"{name}.{k}", v)
    for k in keys:
        if k not in out and k != "hold":
            raise invalid(f"{name}.{k}", "missing", f"a number (m): a {kind} defect has {', '.join(keys)}")
    return out


def with_defects(
    defects: Sequence[Mapping[str, Any]],
    base: Irregularity | None = None,
    *,
    start: float | None = None,
    end: float | None = None,
    step: float | None = None,
) -> Irregularity:
    """Adds isolated defects (``rail_mbs::track::Defect``, metres) to ``base``, or to a perfect
    track sampled over [``start`` (default 0), ``end``] every ``step`` m (default 0.05; ``kind =
    "perfect"``). Each defect is a dict with ``type`` (:data:`DEFECTS`): ``"cosine_dip"``
    (vertical, ``start``, ``length``, ``depth`` positive down), ``"cusp"`` (a dipped joint at
    ``at``, ``length``, ``depth``) or ``"twist"`` (cross-level rising over ``base`` from ``start``
    to ``cross_level``, held for ``hold``, falling over ``base``). Each must lie within the grid
    and span at least 8 sample spacings. Errors name the defect (``defects[1].length``)."""
    if isinstance(defects, Mapping | str) or not isinstance(defects, Sequence):
        raise invalid("defects", defects, "a list of defect dicts")
    items = [_defect(d, i) for i, d in enumerate(defects)]
    if base is not None:
        if not isinstance(base, Irregularity):
            raise invalid("base", base, "an Irregularity (or None: a perfect track)")
        for k, v in (("start", start), ("end", end), ("step", step)):
            if v is not None:
                raise invalid(k, v, "none with a `base` (its grid is used)")
        spec = {**base.spec, "defects": [*base.spec.get("defects", []), *items]}
        samples: dict[str, Any] = base.to_dict()
    else:
        s0 = 0.0 if start is None else _real("start", start)
        if end is None:
            raise invalid("end", None, "the end of the perfect track (m) when no `base` is given")
        s1 = _real("end", end)
        h = 0.05 if step is None else _real("step", step)
        _check_samples(s1 - s0, h, "end")
        samples = _core.track_irregularity_defects([], start=s0, end=s1, step=h)
        spec = {"kind": "perfect", "start": s0, "length": s1 - s0, "step": h, "defects": items}
    for i, d in enumerate(items):
        try:
            samples = _core.track_irregularity_defects([d], samples=samples)
        except ValueError as exc:
            msg = str(exc)
            if msg.startswith("invalid `defects[0]"):
                msg = f"invalid `defects[{i}]" + msg[len("invalid `defects[0]") :]
            elif msg.startswith("invalid `"):
                msg = f"invalid `defects[{i}]." + msg[len("invalid `") :]
            raise ValueError(msg) from exc
    return Irregularity.from_dict(samples, spec)


def file_sha256(path: str | os.PathLike[str]) -> str:
    """The SHA-256 digest (hex) of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def from_spec(spec: Mapping[str, Any]) -> Irregularity:
    """Builds the irregularity a ``spec`` describes (:attr:`Irregularity.spec`; a scene's
    ``[track.irregularities]`` resolved, :meth:`railslosh.scene.Scene.irregularity_spec`):
    ``kind`` a spectrum (the keys of :func:`generate`, ``class`` for ``track_class``), ``"file"``
    (``file``, ``units``, ``start`` where its first sample goes, ``channels`` kept, ``sha256`` the
    file must have) or ``"perfect"`` (``start``, ``length``, ``step``), plus ``defects``. The same
    spec gives the same irregularity, bit for bit (the last few are cached)."""
    if not isinstance(spec, Mapping):
        raise invalid("spec", spec, "a dict with a `kind`")
    try:
        text = json.dumps(dict(spec), sort_keys=True)
    except (TypeError, ValueError) as exc:
        raise invalid("spec", spec, "a JSON-like dict (numbers, strings, lists, dicts)") from exc
    return dataclasses.replace(_from_spec(text), spec=dict(spec))


@functools.lru_cache(maxsize=4)
def _from_spec(text: str) -> Irregularity:
    spec = json.loads(text)
    kind = spec.get("kind")
    defects = spec.get("defects") or []
    if kind in SPECTRA:
        keys = ("length", "start", "step", "wavelengths", "seed", "taper", "channels")
        irr = generate(kind, spec.get("class"), **{k: spec[k] for k in keys if k in spec})
    elif kind == "file":
        if "file" not in spec:
            raise invalid("file", None, 'a file path with kind = "file"')
        irr = read(spec["file"], units=spec.get("units"))
        digest = file_sha256(spec["file"])
        if spec.get("sha256") not in (None, digest):
            raise invalid("sha256", spec["sha256"], f"the digest of {spec['file']!r}, which is {digest} (it changed)")
        if spec.get("start") is not None:
            irr = irr.placed(spec["start"])
        if spec.get("channels") is not None:
            irr = irr.with_channels(spec["channels"])
    elif kind == "perfect":
        start = spec.get("start", 0.0)
        irr = with_defects(defects, start=start, end=start + spec.get("length", 0.0), step=spec.get("step"))
        defects = []
    else:
        raise invalid("kind", kind, f"one of {', '.join(repr(k) for k in (*SPECTRA, 'file', 'perfect'))}")
    if defects:
        irr = with_defects(defects, irr)
    return irr


# --- spectra -----------------------------------------------------------------------------------------


def psd(kind: str, channel: str, omega: Any, track_class: int | None = None) -> np.ndarray:
    """The one-sided target PSD of ``channel`` of spectrum ``kind`` (and ``track_class`` for
    ``"fra"``) at spatial angular frequencies ``omega`` (rad/m, > 0), m² per rad/m
    (``rail_mbs::track::TrackSpectrum::psd``; formulas there). Shaped like ``omega``."""
    kind = _check_kind(kind)
    cls = _check_class(track_class)
    if not isinstance(channel, str) or channel not in CHANNELS:
        raise invalid("channel", channel, f"one of {', '.join(CHANNELS)}")
    try:
        w = np.asarray(omega, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise invalid("omega", omega, "spatial angular frequencies > 0 rad/m") from exc
    flat = np.ascontiguousarray(w.ravel())
    try:
        out = _core.track_psd(kind, channel, flat, track_class=cls)
    except ValueError as exc:
        raise _rename(exc, {"class": "track_class"}) from exc
    return np.asarray(out).reshape(w.shape)


def welch_psd(
    irr: Irregularity, channel: str, nperseg: int = WELCH_NPERSEG, *, start: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Welch estimate of the one-sided PSD of ``channel`` (``scipy.signal.welch``: Hann window,
    ``nperseg`` samples a segment, at most the samples there are, half overlapping, mean removed)
    from the samples at distances ≥ ``start`` (default all): ``(omega, S)`` with the spatial
    angular frequency Ω in rad/m (> 0; the zero frequency is left out) and S in m² per rad/m, the
    units of :func:`psd`."""
    from scipy import signal

    if not isinstance(irr, Irregularity):
        raise invalid("irr", irr, "an Irregularity")
    x = irr.channel(channel)
    if start is not None:
        x = x[irr.distance >= _real("start", start) - 1e-9 * irr.step]
    if isinstance(nperseg, bool) or not isinstance(nperseg, numbers.Integral) or nperseg < 8:
        raise invalid("nperseg", nperseg, "an integer number of samples ≥ 8")
    if len(x) < 8:
        raise invalid("start", start, f"at least 8 samples after it (there are {len(x)})")
    w, p = signal.welch(x, fs=2.0 * np.pi / irr.step, nperseg=min(int(nperseg), len(x)))
    return w[1:], p[1:]


def third_octave_bands(wavelengths: tuple[float, float] = (1.0, 70.0)) -> np.ndarray:
    """The one-third-octave bands within the wavelength range ``wavelengths`` (m): the ISO 266
    bands of centre 10^(n/10) cycles/m, edges at the centre × 10^(±1/20), whose edges both lie
    within [1/longest, 1/shortest] cycles/m; as rows (Ω_low, Ω_high) in rad/m, lowest first.
    For 1–70 m: 17 bands, centre wavelengths 50 m to 1.25 m."""
    lo, hi = (_real("wavelengths[0]", wavelengths[0]), _real("wavelengths[1]", wavelengths[1]))
    if not (0 < lo < hi and math.isfinite(hi)):
        raise invalid("wavelengths", wavelengths, "0 < shortest < longest wavelength (m)")
    f_min, f_max = 1.0 / hi, 1.0 / lo
    n0, n1 = math.floor(10 * math.log10(f_min)) - 1, math.ceil(10 * math.log10(f_max)) + 1
    rows = []
    for n in range(n0, n1 + 1):
        fc = 10.0 ** (n / 10)
        a, b = fc * 10.0 ** (-1 / 20), fc * 10.0 ** (1 / 20)
        if a >= f_min * (1 - 1e-12) and b <= f_max * (1 + 1e-12):
            rows.append((2 * np.pi * a, 2 * np.pi * b))
    return np.array(rows).reshape(-1, 2)


def band_ratios(
    irr: Irregularity,
    channel: str,
    kind: str,
    track_class: int | None = None,
    *,
    wavelengths: tuple[float, float] = (1.0, 70.0),
    nperseg: int = WELCH_NPERSEG,
) -> tuple[np.ndarray, np.ndarray]:
    """The Welch PSD of ``channel`` (:func:`welch_psd`) over the target (:func:`psd`) in each
    one-third-octave band of ``wavelengths`` (:func:`third_octave_bands`): the sum of the estimate
    over the Welch frequencies in the band divided by the sum of the target at the same
    frequencies. Returns ``(bands, ratios)``; 1 is a perfect match."""
    w, p = welch_psd(irr, channel, nperseg)
    target = psd(kind, channel, w, track_class)
    bands = third_octave_bands(wavelengths)
    ratios = []
    for a, b in bands:
        m = (w >= a) & (w < b)
        if not m.any():
            raise invalid("nperseg", nperseg, f"segments long enough to resolve the band {a:.4g}–{b:.4g} rad/m")
        ratios.append(float(p[m].sum() / target[m].sum()))
    return bands, np.array(ratios)


# --- files -------------------------------------------------------------------------------------------


def _bad(path: Path, expected: str) -> ValueError:
    return invalid("file", str(path), expected)


def _format(x: float, units: str) -> str:
    text = repr(float(x))
    if units == "m":
        return text
    if x == 0.0:
        return "-0" if math.copysign(1.0, x) < 0 else "0"
    d = Decimal(text).scaleb(_SCALE[units])
    return format(d, "f") if d.adjusted() >= -7 else str(d)


def write(irr: Irregularity, path: str | os.PathLike[str], units: str = "mm") -> Path:
    """Writes ``irr`` to ``path`` in the file format of the module docs, the channels in
    ``units`` (``"mm"`` or ``"m"``; distances in m): ``# units``, ``# start``, ``# step`` and
    ``# spec`` comment lines, the header, one row per sample. :func:`read` gives back the same
    samples, bit for bit, in both units. Returns the path."""
    if not isinstance(irr, Irregularity):
        raise invalid("irr", irr, "an Irregularity")
    if units not in UNITS:
        raise invalid("units", units, "'mm' or 'm'")
    p = Path(path)
    lines = [
        "# railslosh track irregularity: distance along the track (m) and the channels vertical, alignment,",
        "# cross_level, gauge (docs/frames.md, 'Track irregularities'; format: railslosh.irregularity)",
        f"# units: {units}",
        f"# start: {irr.start!r}",
        f"# step: {irr.step!r}",
        f"# spec: {json.dumps(dict(irr.spec), default=str)}",
        ",".join(_COLUMNS),
    ]
    cols = [irr.distance, *(getattr(irr, c) for c in CHANNELS)]
    for k in range(irr.samples):
        lines.append(",".join([repr(float(cols[0][k])), *(_format(float(c[k]), units) for c in cols[1:])]))
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return p


def _number(text: str) -> Decimal | None:
    try:
        d = Decimal(text.strip())
    except InvalidOperation:
        return None
    return d if d.is_finite() else None


def read(path: str | os.PathLike[str], units: str | None = None) -> Irregularity:
    """Reads an irregularity file (format in the module docs). ``units`` (``"mm"`` or ``"m"``)
    is needed when the file has no ``# units:`` line, and must agree with it when it has one.
    A missing path raises ``FileNotFoundError``, a directory ``IsADirectoryError``; everything
    else ``ValueError`` naming the line and column: missing or unknown columns, a cell that is
    not a finite number, missing or unknown units, fewer than 2 rows, an empty file, distances
    that are not uniformly spaced. ``spec`` is ``{"kind": "file", "file": <absolute path>,
    "units", "sha256"}``."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"invalid `file` = {str(p)!r}: no such file; expected a track irregularity file")
    if p.is_dir():
        raise IsADirectoryError(f"invalid `file` = {str(p)!r}: a directory; expected a track irregularity file")
    if units is not None and units not in UNITS:
        raise invalid("units", units, "'mm' or 'm'")
    raw = p.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _bad(p, f"UTF-8 text (not at byte {exc.start})") from exc
    meta: dict[str, tuple[int, str]] = {}
    header: list[str] | None = None
    rows: list[tuple[int, list[Decimal]]] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, sep, value = s[1:].partition(":")
            if sep and key.strip().lower() in ("units", "start", "step"):
                meta[key.strip().lower()] = (lineno, value.strip())
            continue
        cells = [c.strip() for c in s.split(",")]
        if header is None:
            for i, name in enumerate(cells):
                if name not in _COLUMNS:
                    close = suggest(name, _COLUMNS)
                    hint = f" (did you mean {close!r}?)" if close else ""
                    raise _bad(p, f"the columns {', '.join(_COLUMNS)}; line {lineno} column {i + 1} is {name!r}{hint}")
                if cells.count(name) > 1:
                    raise _bad(p, f"each column once; line {lineno} has {name!r} twice")
            absent = [c for c in _COLUMNS if c not in cells]
            if absent:
                raise _bad(
                    p, f"the columns {', '.join(_COLUMNS)}; the header (line {lineno}) lacks {', '.join(absent)}"
                )
            header = cells
            continue
        if len(cells) != len(header):
            raise _bad(p, f"{len(header)} cells a row; line {lineno} has {len(cells)}")
        values = []
        for name, cell in zip(header, cells, strict=True):
            d = _number(cell)
            if d is None:
                unit = "m" if name == "distance" else "the file's units"
                raise _bad(p, f"a finite number ({unit}) in every cell; line {lineno}, column `{name}` is {cell!r}")
            values.append(d)
        rows.append((lineno, values))
    if header is None:
        raise _bad(p, "a header line and rows (the file is empty" + (", only comments)" if text.strip() else ")"))
    if len(rows) < 2:
        raise _bad(p, f"at least 2 rows of samples (there {'is' if len(rows) == 1 else 'are'} {len(rows)})")
    file_units = meta.get("units", (0, ""))[1] or None
    if file_units is not None and file_units not in UNITS:
        raise _bad(p, f"'# units: mm' or '# units: m'; line {meta['units'][0]} says {file_units!r}")
    if file_units is None and units is None:
        raise _bad(p, "a '# units: mm' or '# units: m' comment line (or the `units` argument)")
    if file_units is not None and units is not None and file_units != units:
        raise invalid("units", units, f"the units of {str(p)!r}, which says {file_units!r} (line {meta['units'][0]})")
    u = file_units or units
    assert u is not None
    col = {name: i for i, name in enumerate(header)}
    dist = np.array([float(v[col["distance"]]) for _, v in rows])
    scale = -_SCALE[u]
    chans = {c: np.array([float(v[col[c]].scaleb(scale)) for _, v in rows]) for c in CHANNELS}
    n = len(rows)
    start, step = float(dist[0]), float((dist[-1] - dist[0]) / (n - 1))
    for key in ("start", "step"):
        if key in meta:
            d = _number(meta[key][1])
            if d is None:
                raise _bad(p, f"a number (m) after '# {key}:'; line {meta[key][0]} has {meta[key][1]!r}")
            if key == "start":
                start = float(d)
            else:
                step = float(d)
    if not step > 0:
        raise _bad(p, f"increasing distances; line {rows[1][0]} has {float(dist[1])!r} m after {start!r} m")
    grid = start + step * np.arange(n, dtype=np.float64)
    off = np.flatnonzero(np.abs(dist - grid) > UNIFORM_TOLERANCE * step)
    if off.size:
        k = int(off[0])
        raise _bad(
            p,
            f"uniformly spaced distances (every {step!r} m from {start!r} m, to {UNIFORM_TOLERANCE:.1%} of the "
            f"spacing); line {rows[k][0]} has {float(dist[k])!r} m, expected {float(grid[k])!r} m",
        )
    spec = {"kind": "file", "file": str(p.resolve()), "units": u, "sha256": hashlib.sha256(raw).hexdigest()}
    return Irregularity(start, step, *(chans[c] for c in CHANNELS), spec=spec)


# --- validation case (railslosh validate track-irregularity) -----------------------------------------

PSD_TOLERANCE = 0.15
"""Largest deviation of a one-third-octave band's Welch/target ratio from 1 (issue 20 §1)."""


def _validation(quick: bool) -> list[dict[str, object]]:
    from railslosh.records import record, within

    case = "track-irregularity"
    if quick:
        spectra: list[tuple[str, int | None]] = [("fra", 5), ("erri_high", None)]
        length = 6000.0
    else:
        spectra = [("fra", c) for c in range(1, 7)] + [("erri_low", None), ("erri_high", None)]
        length = 12000.0
    out: list[dict[str, object]] = []
    nb = len(third_octave_bands())
    for seed, (kind, cls) in enumerate(spectra, 1):
        irr = generate(kind, cls, length=length, seed=seed)  # another realization for each spectrum
        name = f"FRA class {cls}" if kind == "fra" else {"erri_low": "ERRI low", "erri_high": "ERRI high"}[kind]
        for c in CHANNELS:
            if not np.any(irr.channel(c)):
                continue  # no spectrum for this channel (ERRI gauge)
            _, r = band_ratios(irr, c, kind, cls)
            worst = float(r[np.argmax(np.abs(r - 1.0))])
            q = (
                f"{name} {c}: Welch/target PSD in the worst of {nb} one-third-octave bands (1.25-50 m), "
                f"{length / 1000:g} km, seed {seed}, nperseg {WELCH_NPERSEG} (min {r.min():.3f}, max {r.max():.3f})"
            )
            out.append(within(case, q, worst, 1.0, PSD_TOLERANCE))
    a = generate("fra", 5, length=500.0, seed=7)
    b = generate("fra", 5, length=500.0, seed=7)
    diff = max(float(np.max(np.abs(a.channel(c) - b.channel(c)))) for c in CHANNELS)
    out.append(record(case, "same seed, same track: largest sample difference (m, bitwise 0)", diff, 0.0, 0.0, a == b))
    other = generate("fra", 5, length=500.0, seed=8)
    rel = float(np.sqrt(np.mean((other.vertical - a.vertical) ** 2)) / np.sqrt(np.mean(a.vertical**2)))
    out.append(
        record(case, "another seed, another track: RMS difference / RMS (vertical; sqrt 2 expected)", rel, 0.5, 0.0,
               rel > 0.5)
    )  # fmt: skip
    return out


VALIDATION_CASES = {
    "track-irregularity": (
        "generated track irregularity vs its spectrum: Welch PSD within 15 % of the target in each of the 17 "
        "one-third-octave bands of 1-70 m, every channel (quick: FRA class 5 and ERRI high, 6 km; full: FRA 1-6, "
        "ERRI low and high, 12 km; seeds 1, 2, ... in that order), and the same seed gives the same track",
        _validation,
    )
}
"""``railslosh validate`` cases of this module (name -> (description, run(quick) -> records))."""
