"""docs/api.md documents every public name of the Python modules (regenerate it with
``python -m railslosh.apidoc > docs/api.md``), and the user guide's commands name real options."""

import importlib
import inspect
from pathlib import Path

import pytest

from railslosh import apidoc, cli

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("module", [m for m in apidoc.MODULES if m != "railslosh"])
def test_api_reference_lists_every_public_name(module):
    text = (ROOT / "docs" / "api.md").read_text()
    mod = importlib.import_module(module)
    assert f"## `{module}`" in text
    for name in apidoc._public(mod):
        obj = getattr(mod, name)
        if inspect.ismodule(obj) or getattr(obj, "__module__", module) != module:
            continue  # re-exports are documented where they are defined
        assert f"`{name}" in text or f"`{mod.__name__.split('.')[-1]}.{name}" in text, f"{module}.{name} missing"


def test_generated_reference_covers_the_tool_modules():
    text = apidoc.generate()
    for name in ("load_scene", "run_sweep", "to_dataset", "write_vtu", "write_report", "plot_dataset", "ProgressBar"):
        assert name in text


def test_user_guide_commands_use_existing_subcommands_and_options():
    guide = (ROOT / "docs" / "user-guide.md").read_text()
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    blocks = guide.split("```")[1::2]  # the code blocks
    lines = [ln.strip() for b in blocks for ln in b.splitlines() if ln.strip().startswith("railslosh ")]
    lines = [ln for ln in lines if not ln.split()[1].endswith(":")]  # printed messages, not commands
    assert len(lines) >= 4
    for ln in lines:
        words = ln.split()
        assert words[1] in sub.choices, ln
        opts = {o for a in sub.choices[words[1]]._actions for o in a.option_strings}
        for w in words[2:]:
            if w.startswith("-"):
                assert w.split("=")[0] in opts, f"{w} in: {ln}"
    for ex in {w for ln in lines for w in ln.split() if w.startswith("examples/")}:
        assert (ROOT / ex).is_file(), ex
