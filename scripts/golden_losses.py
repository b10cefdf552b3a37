"""Write the golden losses the training tests compare against.

    .venv/bin/python scripts/golden_losses.py

Builds the tiny Gemma 3 of ``ara.training.tiny``, runs the two steps of ``GOLDEN_RUN``
on the paper split and writes their losses, with what produced them, to
``tests/training/golden_losses.json``. Rerun it only when a change to the recipe is
meant to change the numbers, and say so in the commit.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import torch
import transformers

from ara import __version__
from ara.provenance import git_commit
from ara.training.config import TrainConfig
from ara.training.hf_model import prepare_base_model
from ara.training.recipe import LoRAFinetuneRecipe
from ara.training.tiny import GOLDEN_RUN, build_tiny_gemma

TARGET = Path(__file__).resolve().parents[1] / "tests" / "training" / "golden_losses.json"


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        model = build_tiny_gemma(Path(tmp, "tiny"), prepare_base_model())
        config = TrainConfig.from_dict({**GOLDEN_RUN, "base_model": model,
                                        "out": str(Path(tmp, "run"))})
        recipe = LoRAFinetuneRecipe(config)
        recipe.setup()
        losses = recipe.train()
    TARGET.write_text(json.dumps({
        "losses": losses, "run": GOLDEN_RUN,
        "produced_by": {"script": "scripts/golden_losses.py", "ara": __version__,
                        "git_commit": git_commit(), "torch": torch.__version__,
                        "transformers": transformers.__version__}}, indent=2) + "\n")
    print(f"wrote {TARGET}: {losses}")


if __name__ == "__main__":
    main()
