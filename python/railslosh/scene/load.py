"""Loading scenes: a TOML file, TOML text or a parsed dict, with overrides
(``section.key=VALUE`` on the command line), dispatched to the vehicle or slosh schema."""

from __future__ import annotations

import os
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from railslosh.limits import invalid
from railslosh.scene.schema import merge, table
from railslosh.scene.slosh import SloshScene, slosh_scene_from_dict
from railslosh.scene.vehicle import Scene, scene_from_dict

_KINDS = "a vehicle scene ([track], [train], ...) or a slosh scene ([maneuver], [tank], ...)"


def _is_path(source: str | os.PathLike[str]) -> bool:
    """A string names a file unless it reads as TOML text: one line, ending in ``.toml`` or naming
    something that exists, or with neither ``=`` nor ``[`` (which every TOML document has)."""
    if isinstance(source, os.PathLike):
        return True
    if "\n" in source or not source.strip():
        return False
    return source.endswith(".toml") or Path(source).exists() or not any(c in source for c in "=[")


def read_scene(source: str | os.PathLike[str] | Mapping[str, Any]) -> dict[str, Any]:
    """The parsed document of a scene file (path), TOML text or dict. A path that does not exist
    raises ``FileNotFoundError``, a directory ``IsADirectoryError``; TOML syntax, non-UTF-8 text
    and an empty scene raise ``ValueError`` saying so. A scene file's relative
    ``[track.irregularities] file`` is made relative to the scene file's folder (from text or a
    dict it stays relative to the working directory)."""
    if isinstance(source, Mapping):
        data = dict(source)
        if not data:
            raise invalid("scene", data, f"{_KINDS}; this one is empty")
        return data
    where = ""
    if _is_path(source):
        path = Path(source)
        if not path.exists():
            raise FileNotFoundError(f"invalid `scene` = {str(path)!r}: no such file; expected a scene file (TOML)")
        if path.is_dir():
            raise IsADirectoryError(f"invalid `scene` = {str(path)!r}: a directory; expected a scene file (TOML)")
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError as exc:
            raise ValueError(
                f"invalid `scene` = {str(path)!r}: not UTF-8 text ({exc.reason} at byte {exc.start}); "
                "expected a scene file (TOML)"
            ) from exc
        where = f" in {path}"
    else:
        text = str(source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"invalid scene TOML{where}: {exc}") from exc
    if not data:
        shown = str(source) if where else text
        raise invalid("scene", shown, f"{_KINDS}; the {'file' if where else 'text'} is empty (no sections)")
    if where:
        _relative_to(data, Path(source).parent)
    return data


def _relative_to(data: dict[str, Any], folder: Path) -> None:
    """A relative ``[track.irregularities] file`` of a scene file is relative to its folder."""
    irr = data.get("track", {}).get("irregularities") if isinstance(data.get("track"), dict) else None
    if isinstance(irr, dict) and isinstance(irr.get("file"), str) and irr["file"]:
        p = Path(irr["file"]).expanduser()
        if not p.is_absolute():
            irr["file"] = str(folder / p)


def load_scene(
    source: str | os.PathLike[str] | Mapping[str, Any], overrides: Mapping[str, Any] | None = None
) -> Scene | SloshScene:
    """Loads and validates a scene from a TOML file (path), TOML text or an already parsed dict.

    ``overrides`` is merged into the parsed scene section by section before validation, e.g.
    ``{"train": {"t_end": 0.1}}``; a value ``None`` removes that key. A string is read as a file
    path when it is one line that ends in ``.toml``, names an existing file or directory, or has
    neither ``=`` nor ``[``; otherwise as TOML text. A missing file raises ``FileNotFoundError``, a
    directory ``IsADirectoryError``; every other error is a ``ValueError`` naming the dotted field
    (``invalid `train.t_end` = -1.0: expected a time > 0 s and ≤ 600 s``), also TOML syntax errors,
    unknown sections and keys (with the closest allowed name) and an empty scene.
    """
    data: Mapping[str, Any] = read_scene(source)
    if overrides is not None:
        data = merge(table(data, "scene"), table(overrides, "overrides"))
    if "maneuver" in data:
        return slosh_scene_from_dict(data)
    return scene_from_dict(data)


def parse_value(text: str) -> Any:
    """A TOML value (``0.5``, ``true``, ``[1, 2]``, ``"x"``), or the bare text as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text.strip()


NESTED = (("track", "irregularities"),)
"""Tables inside a section whose keys ``--set`` and ``--grid`` reach as ``section.table.key``."""


def set_dotted(over: dict[str, Any], dotted: str, value: Any, option: str = "--set") -> None:
    """Sets ``over[section][key] = value`` for ``dotted = "section.key"`` (``over[section][table][key]``
    for ``"track.irregularities.key"``, :data:`NESTED`); ``option`` names the source in the error."""
    keys = dotted.strip().split(".")
    nested = len(keys) == 3 and tuple(keys[:2]) in NESTED
    if not (len(keys) == 2 or nested) or not all(keys):
        raise invalid(option, dotted, "a field section.key (e.g. train.t_end) or track.irregularities.key")
    node = over
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    node[keys[-1]] = value


def parse_overrides(items: Iterable[str], option: str = "--set") -> dict[str, Any]:
    """``["train.t_end=0.5", "fluid.oil=heavy"]`` -> ``{"train": {"t_end": 0.5}, "fluid": {"oil":
    "heavy"}}``; values are TOML (bare words are strings)."""
    over: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise invalid(option, item, "section.key=VALUE (a TOML value), e.g. train.t_end=0.5")
        set_dotted(over, key, parse_value(value), option)
    return over
