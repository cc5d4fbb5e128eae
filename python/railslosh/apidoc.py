"""Writes the API reference (``docs/api.md``) from the docstrings and signatures of the public
Python modules: ``python -m railslosh.apidoc > docs/api.md``."""

from __future__ import annotations

import importlib
import inspect
import sys

MODULES = (
    "railslosh",
    "railslosh.mesh",
    "railslosh.fluids",
    "railslosh.body",
    "railslosh.slosh",
    "railslosh.rail",
    "railslosh.irregularity",
    "railslosh.vehicle",
    "railslosh.scene",
    "railslosh.limits",
    "railslosh.fluid_model",
    "railslosh.results",
    "railslosh.indicators",
    "railslosh.plots",
    "railslosh.report",
    "railslosh.sweep",
    "railslosh.bench",
    "railslosh.robustness",
    "railslosh.cosim",
    "railslosh.fmu",
    "railslosh.progress",
    "railslosh.cli",
)


def _public(mod: object) -> list[str]:
    names = getattr(mod, "__all__", None)
    if names is None:
        names = [n for n in vars(mod) if not n.startswith("_")]
    return [n for n in names if hasattr(mod, n)]


def _doc(obj: object) -> str:
    return inspect.cleandoc(obj.__doc__) if obj.__doc__ else "(undocumented)"


def _sig(obj: object) -> str:
    try:
        return str(inspect.signature(obj))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return "(...)"


def generate() -> str:
    out = [
        "# API reference",
        "",
        "Generated from the docstrings by `python -m railslosh.apidoc > docs/api.md` (a test checks it is",
        "current). Units are SI; frames and signs are defined in `docs/frames.md`. The compiled kernels are",
        "`railslosh._core` (signatures in `python/railslosh/_core.pyi`, checked by mypy's stubtest).",
        "",
    ]
    for name in MODULES:
        mod = importlib.import_module(name)
        out += [f"## `{name}`", "", _doc(mod), ""]
        for n in _public(mod):
            obj = getattr(mod, n)
            if inspect.ismodule(obj) or getattr(obj, "__module__", name) not in (name, "railslosh._core"):
                if not (name == "railslosh" and not inspect.ismodule(obj)):
                    continue
            if inspect.isclass(obj):
                out += [f"### class `{n}{_sig(obj)}`", "", _doc(obj), ""]
                for m, member in vars(obj).items():
                    if m.startswith("_") or not (inspect.isfunction(member) or isinstance(member, property)):
                        continue
                    target = member.fget if isinstance(member, property) else member
                    sig = "" if isinstance(member, property) else _sig(member)
                    out += [f"#### `{n}.{m}{sig}`", "", _doc(target), ""]
            elif callable(obj):
                out += [f"### `{n}{_sig(obj)}`", "", _doc(obj), ""]
            else:
                out += [f"### `{n}`", "", f"`{obj!r}`"[:300], ""]
    return "\n".join(out).rstrip() + "\n"


if __name__ == "__main__":
    sys.stdout.write(generate())
