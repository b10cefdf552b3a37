"""A staged recipe: a translator rebuilt from the base model by one command.

    ara train --config training/configs/gemma3_270m_nl2tl.yaml     # rerun to continue

A recipe config names an ``out`` folder, the ``defaults`` every training stage starts
from (the keys of a single-run config, :class:`~ara.training.config.TrainConfig`) and
its ``stages``, in order, each one of:

- ``train: {...}``: a LoRA run, its settings laid over ``defaults``; with
  ``from: STAGE`` it warm-starts from that stage's adapter;
- ``soup: [STAGE, ...]``: the average of those stages' adapters (``weights``, optional),
  reduced to ``rank`` when given (:func:`~ara.training.soup.soup_runs`);
- ``export: STAGE``: that stage's adapter as a GGUF LoRA for llama.cpp, with the greedy
  parity check of the GGUF against transformers (:func:`~ara.training.export.export_checked`).

Each stage writes ``OUT/NAME/`` and reads only the folders of the stages it names, so the
recipe needs nothing but the base model and the registered data. A stage is done when
``OUT/NAME/stage.json`` holds ``done: true`` and the fingerprint of its settings (with
the data version this release registers, where they leave it to the release) and of its
inputs' fingerprints. :func:`~ara.training.stage_runner.run_recipe` runs them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ara.errors import ConfigError, did_you_mean, refuse_unknown_keys
from ara.provenance import sha256_file
from ara.training.config import BOOKKEEPING, SHIPPED_ADAPTERS, TrainConfig
from ara.training.export import PARITY_PAIRS
from ara.training.run_folder import adapter_identity
from ara.training.soup import check_soup

KINDS = ("train", "soup", "export")
# Where a rebuilt training stage's old folder goes: hours of training are not deleted by
# an edit, nor by a release whose settings read differently.
REPLACED = "replaced"


@dataclass(frozen=True)
class Stage:
    """One step of a recipe.

    Args:
        name: Folder name under the recipe's ``out``; letters, digits, ``-`` and ``_``.
        kind: ``train``, ``soup`` or ``export``.
        settings: For ``train``, the run's config laid over the recipe's ``defaults``
            (``out`` and ``init_adapter`` are the recipe's to set); for ``soup``,
            ``weights`` and ``rank``; for ``export``, ``parity`` (test pairs, default 20).
        inputs: The stages it reads: a training stage's ``from``, a soup's parts, what
            an export exports.
    """

    name: str
    kind: str
    settings: dict = field(default_factory=dict)
    inputs: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.name or not all(c.isalnum() or c in "-_" for c in self.name):
            raise ConfigError(f"stage name {self.name!r}: use letters, digits, '-' and '_'")
        if self.name == REPLACED:
            raise ConfigError(f"stage name {REPLACED!r} is the recipe's folder for rebuilt "
                              "stages' old folders; choose another")
        if self.kind not in KINDS:
            raise ConfigError(f"stage {self.name}: kind {self.kind!r} is not one of {KINDS}")
        if self.kind == "export" and len(self.inputs) != 1:
            raise ConfigError(f"stage {self.name}: export names exactly one stage")


@dataclass(frozen=True)
class StagedRecipe:
    """A recipe's stages and where they write.

    Args:
        out: The recipe's folder; stage ``NAME`` writes ``out/NAME``.
        defaults: Settings every training stage starts from.
        stages: In the order they run; each reads only stages before it.
    """

    out: Path
    defaults: dict
    stages: tuple[Stage, ...]

    def __post_init__(self) -> None:
        seen: dict[str, Stage] = {}
        for stage in self.stages:
            if stage.name in seen:
                raise ConfigError(f"two stages are named {stage.name}")
            for name in stage.inputs:
                if name not in seen:
                    raise ConfigError(f"stage {stage.name} reads {name!r}, which is not a "
                                      f"stage before it. {did_you_mean(name, seen)}")
                if seen[name].kind == "export":
                    raise ConfigError(f"stage {stage.name} reads {name}, an export: name the "
                                      "stage whose adapter it exported")
            seen[stage.name] = stage
        if not self.stages:
            raise ConfigError("a recipe needs at least one stage")
        for stage in self.stages:
            if stage.kind == "train":
                self.train_config(stage)  # each stage's run config checks its own ranges

    @classmethod
    def from_dict(cls, data: dict) -> StagedRecipe:
        refuse_unknown_keys(data, {"out", "defaults", "stages"})
        if "out" not in data or not isinstance(data.get("stages"), list):
            raise ConfigError("a recipe needs `out` and a list of `stages`")
        return cls(Path(data["out"]), dict(data.get("defaults") or {}),
                   tuple(_stage(item) for item in data["stages"]))

    def folder(self, name: str) -> Path:
        return self.out / name

    def train_config(self, stage: Stage) -> TrainConfig:
        """The single-run config of a training stage: ``defaults`` with the stage's
        settings laid over them (sections merged key by key), writing into its folder."""
        for key in ("out", "init_adapter"):
            if key in stage.settings:
                raise ConfigError(f"stage {stage.name}: {key} is set by the recipe "
                                  "(the stage's folder, and `from:`)")
        merged = _merged(self.defaults, stage.settings)
        merged["out"] = str(self.folder(stage.name))
        if stage.inputs:
            merged["init_adapter"] = str(self.folder(stage.inputs[0]) / "adapter")
        return TrainConfig.from_dict(merged)

    def fingerprints(self, max_steps: int | None = None) -> dict[str, str]:
        """Each stage's identity: its kind, settings and its inputs' fingerprints;
        ``max_steps``, a smoke run's cap on every training stage (``--max-steps``),
        makes each stage another one."""
        prints: dict[str, str] = {}
        for stage in self.stages:
            settings = stage.settings
            if stage.kind == "train":
                # A stage trained with the held-out check off (say, on a GPU box without
                # Spot) counts as done where the check is on.
                config = self.train_config(stage)
                # Precision is how a machine computes the run, as a resumed run may
                # change it: not what the stage is.
                settings = {k: v for k, v in config.to_dict().items()
                            if k not in BOOKKEEPING and k != "precision"}
                # "The version this release registers" names other data once a release
                # registers another: a stage trained on the old one is stale.
                settings["data"] = {**settings["data"],
                                    "version": config.data.resolved_version()}
                # What a file holds, not its name: a user's pairs edited, or a warm start
                # from an adapter a release replaced (init_adapter: finetuned), is another
                # stage. (Keys only where set, so other stages keep their fingerprints.)
                if config.data.pairs:
                    settings["data"]["pairs_sha256"] = _file_hash(config.data.pairs)
                if config.init_adapter and not stage.inputs:
                    # A shipped file by its own hash: `--status` converts nothing.
                    shipped = SHIPPED_ADAPTERS.get(config.init_adapter)
                    settings["init_adapter_sha256"] = (
                        sha256_file(shipped) if shipped else
                        (adapter_identity(config.init_adapter_folder) or {}).get("sha256"))
            blob = json.dumps({"kind": stage.kind, "settings": settings,
                               "inputs": [prints[name] for name in stage.inputs]},
                              sort_keys=True)
            prints[stage.name] = hashlib.sha256(blob.encode()).hexdigest()[:16]
        if max_steps is not None:
            prints = {k: f"{v}-max{max_steps}" for k, v in prints.items()}
        return prints


def _file_hash(path: str) -> str | None:
    from ara.provenance import sha256_file

    return sha256_file(path) if Path(path).is_file() else None


def _stage(item: Any) -> Stage:
    if not isinstance(item, dict) or "name" not in item:
        raise ConfigError(f"each stage is a mapping with a name, got {item!r}")
    item = dict(item)
    name = item.pop("name")
    kinds = [k for k in KINDS if k in item]
    if len(kinds) != 1:
        raise ConfigError(f"stage {name}: give exactly one of {', '.join(KINDS)}")
    kind = kinds[0]
    if kind == "train":
        settings, source = item.pop("train") or {}, item.pop("from", None)
        inputs = (source,) if source else ()
    elif kind == "soup":
        parts = item.pop("soup") or ()
        if not isinstance(parts, list) or not all(isinstance(p, str) for p in parts):
            raise ConfigError(f"stage {name}: soup lists the stages it averages, "
                              f"e.g. [refine-a, refine-b]; got {parts!r}")
        inputs = tuple(parts)
        settings = {k: item.pop(k) for k in ("weights", "rank") if k in item}
        try:
            check_soup(len(inputs), settings.get("weights"), settings.get("rank"), "stage")
        except ConfigError as err:
            raise ConfigError(f"stage {name}: {err}") from None
    else:
        source = item.pop("export")
        if not isinstance(source, str):
            raise ConfigError(f"stage {name}: export names one stage, e.g. soup; "
                              f"got {source!r}")
        inputs = (source,)
        settings = {k: item.pop(k) for k in ("parity",) if k in item}
        parity = settings.get("parity", PARITY_PAIRS)
        if not isinstance(parity, int) or isinstance(parity, bool) or parity < 0:
            raise ConfigError(f"stage {name}: parity is a number of test pairs (0: no "
                              f"check), got {parity!r}")
    if item:
        raise ConfigError(f"stage {name}: unknown keys {sorted(item)} for a {kind} stage")
    if not isinstance(settings, dict):
        raise ConfigError(f"stage {name}: train settings must be a mapping")
    return Stage(name, kind, settings, inputs)


def _merged(base: dict, over: dict) -> dict:
    out = dict(base)
    for key, value in over.items():
        out[key] = (_merged(out[key], value) if isinstance(value, dict)
                    and isinstance(out.get(key), dict) else value)
    return out


def is_staged(data: dict) -> bool:
    """Whether a config file's contents are a staged recipe rather than a single run."""
    return isinstance(data, dict) and "stages" in data
