"""``python -m railslosh.scene > docs/scenes.md``: the reference of every scene section and key."""

import sys

from railslosh.scene.schema import reference

sys.stdout.write(reference())
