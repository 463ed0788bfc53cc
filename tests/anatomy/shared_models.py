"""Where the published models that the project does not ship are read from, when they are present.

The three openly licensed lumbar models (docs/anatomy.md, "Published models") sit in a ``shared/models``
folder beside the checkout (CI has it); ``$SPINECTL_SHARED_MODELS`` names another. Tests that read them skip
with :data:`ABSENT` when the folder is not there; the project never copies them.
"""

from __future__ import annotations

import os
from pathlib import Path

SHARED_MODELS = Path(
    os.environ.get("SPINECTL_SHARED_MODELS") or Path(__file__).resolve().parents[3] / "shared" / "models"
)
"""The folder of the published models: ``$SPINECTL_SHARED_MODELS``, else ``../shared/models`` beside the checkout."""

ABSENT = f"the shared downloaded models ({SHARED_MODELS}) are absent"
"""The reason a test that reads them gives when it skips."""

POSE2SIM = SHARED_MODELS / "pose2sim-beaucage-gauvreau" / "Model_Pose2Sim_muscles_flex.osim"
CYCLIST = SHARED_MODELS / "allaire-cyclist"
CHRISTOPHY = SHARED_MODELS / "christophy-skeleton" / "Christophy2012_axialRotationUpd_skeletonOnly.osim"

DOCUMENTED_MAPPINGS = Path(__file__).resolve().parents[2] / "docs" / "mappings"
"""The published models' mappings that docs/anatomy.md shows ("Published models"): ``pose2sim.toml``,
``cyclist.toml``, ``christophy.toml``."""
