"""Deprecated alias of :mod:`railslosh.robustness` (the robustness test matrix; "stress" read as
the stress tensor to a mechanics reader). Importing it warns and gives the same module; it will
be removed in the next release."""

import sys
import warnings

from railslosh import robustness

warnings.warn(
    "railslosh.stress is deprecated: use railslosh.robustness (the same module)", DeprecationWarning, stacklevel=2
)
sys.modules[__name__] = robustness
