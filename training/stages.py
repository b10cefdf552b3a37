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
inputs' fingerprints. A rerun skips done stages, resumes an interrupted training
stage from its newest checkpoint and runs again, from scratch, a stage whose settings or
inputs changed (its old folder removed), so that every stage after an edited one is
rebuilt too. ``OUT/recipe.json`` records each stage's wall time and memory.
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ara.errors import ConfigError, did_you_mean, refuse_unknown_keys
from ara.training.config import BOOKKEEPING, TrainConfig
from ara.training.run_folder import adapter_identity, exclusive, whole_checkpoints
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

    def fingerprints(self) -> dict[str, str]:
        """Each stage's identity: its kind, settings and its inputs' fingerprints."""
        prints: dict[str, str] = {}
        for stage in self.stages:
            settings = stage.settings
            if stage.kind == "train":
                # A stage trained with the held-out check off (say, on a GPU box without
                # Spot) counts as done where the check is on.
                config = self.train_config(stage)
                settings = {k: v for k, v in config.to_dict().items() if k not in BOOKKEEPING}
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
                    settings["init_adapter_sha256"] = (
                        adapter_identity(config.init_adapter_folder) or {}).get("sha256")
            blob = json.dumps({"kind": stage.kind, "settings": settings,
                               "inputs": [prints[name] for name in stage.inputs]},
                              sort_keys=True)
            prints[stage.name] = hashlib.sha256(blob.encode()).hexdigest()[:16]
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
        parity = settings.get("parity", 20)
        if not isinstance(parity, int) or parity < 0:
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


# -- running ----------------------------------------------------------------------------

def _state(folder: Path) -> dict | None:
    """A stage folder's record; ``None`` where it has none (or one a crash left unread-
    able: the stage is then rebuilt, its folder set aside)."""
    path = folder / "stage.json"
    try:
        return json.loads(path.read_text()) if path.is_file() else None
    except json.JSONDecodeError:
        return None


def _write_state(folder: Path, state: dict) -> None:
    """Replace the record whole: a kill leaves the old one or the new one."""
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / "stage.json.tmp"
    tmp.write_text(json.dumps(state, indent=2, sort_keys=True) + "\n")
    tmp.replace(folder / "stage.json")


def _peak_memory() -> dict:
    """The process's resident high-water mark so far (MB), and the GPU's since the last
    reset where there is one."""
    rss_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    peak = {"peak_rss_mb": round(rss_kb / (1024 if sys.platform != "darwin" else 1024**2), 1)}
    import torch

    if torch.cuda.is_available():
        peak["peak_cuda_mb"] = round(torch.cuda.max_memory_allocated() / 2**20, 1)
        torch.cuda.reset_peak_memory_stats()
    return peak


def _stale(recipe: StagedRecipe, stage: Stage, state: dict | None, ran: set[str],
           same: bool) -> str:
    """Why the folder of ``stage`` cannot be kept, in words for the log (``same``: its
    settings and inputs are those it was made with)."""
    if same:
        return ("it stopped before its first checkpoint" if stage.kind == "train"
                else "it stopped before it was done")
    if ran.intersection(stage.inputs):
        return "a stage it reads was rebuilt"
    run = recipe.folder(stage.name) / "run.json"
    if stage.kind == "train" and run.is_file():
        data = recipe.train_config(stage).data
        trained = json.loads(run.read_text())["data"]["version"]
        wanted = data.resolved_version()
        if trained != wanted:
            return (f"it was trained on {data.split} version {trained} and this run asks for "
                    f"{wanted} (to keep it, pin data.version: {trained} in the config, "
                    "where that version is still prepared)")
    if state is None:
        return "its folder holds no stage record"
    return "its settings changed" if run.is_file() or stage.kind != "train" else (
        "it stopped before its run began")


def _has_training(folder: Path) -> bool:
    return (folder / "adapter").is_dir() or bool(whole_checkpoints(folder))


def _set_aside(recipe: StagedRecipe, folder: Path) -> Path:
    """Move a stage's folder under ``out/replaced/``, named by when it was replaced."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    dest, n = recipe.out / REPLACED / f"{folder.name}-{stamp}", 1
    while dest.exists():
        n += 1
        dest = dest.with_name(f"{folder.name}-{stamp}-{n}")
    dest.parent.mkdir(parents=True, exist_ok=True)
    shutil.move(str(folder), str(dest))
    return dest


def _write_record(path: Path, record: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(record, indent=2, sort_keys=True) + "\n")


def _restore(recipe: StagedRecipe, name: str, fingerprint: str, log) -> dict | None:
    """Bring back the newest folder of stage ``name`` set aside with this very
    fingerprint (an edit undone, a data version pinned again), done or resumable,
    setting aside what stands in its place; returns its stage record, else ``None``."""
    folder = recipe.folder(name)
    if (_state(folder) or {}).get("fingerprint") == fingerprint:
        return None
    for old in sorted((recipe.out / REPLACED).glob(f"{name}-*"), reverse=True):
        state = _state(old)
        if state and state.get("name") == name and state.get("fingerprint") == fingerprint \
                and (state.get("done") or whole_checkpoints(old)):
            kept = None
            if folder.exists():
                if _has_training(folder):
                    kept = _set_aside(recipe, folder)
                else:
                    shutil.rmtree(folder)
            shutil.move(str(old), str(folder))
            log(f"stage {name}: brought back from {old} (made with these settings)"
                + (f"; the folder in its place is kept as {kept}" if kept else ""))
            return state
    return None


def _run_stage(recipe: StagedRecipe, stage: Stage, resume: bool,
               max_steps: int | None) -> dict:
    folder = recipe.folder(stage.name)
    if stage.kind == "train":
        from ara.training.recipe import run_training

        config = recipe.train_config(stage)
        if max_steps is not None:
            capped = min(config.max_steps or max_steps, max_steps)
            config = TrainConfig.from_dict({**config.to_dict(), "max_steps": capped})
        return run_training(config, resume)
    if stage.kind == "soup":
        from ara.training.soup import soup_runs

        record = soup_runs([recipe.folder(name) for name in stage.inputs],
                           stage.settings.get("weights"), folder, stage.settings.get("rank"))
        return {k: record[k] for k in ("soup", "reduced") if k in record}
    from ara.training.export import export_checked

    source = recipe.folder(stage.inputs[0])
    manifest = export_checked(source, ("f16",), lora_gguf=True,
                              parity_pairs=stage.settings.get("parity", 20))
    # The export lives in its own stage folder, so that rerunning it leaves the
    # adapter it read alone.
    if folder.exists():
        shutil.rmtree(folder)
    shutil.move(str(source / "export"), str(folder))
    # With the record of the run it exports and its adapter (shipped as PEFT beside the
    # GGUF), the folder is all that shipping needs.
    shutil.copyfile(source / "run.json", folder / "run.json")
    shutil.copytree(source / "adapter", folder / "adapter")
    return {"files": manifest["files"], "parity": manifest.get("parity")}


def run_recipe(recipe: StagedRecipe, max_steps: int | None = None, log=print) -> dict:
    """Run the stages that are not done; returns the recipe's record (``recipe.json``).
    One at a time on a recipe's folder (:func:`~ara.training.run_folder.exclusive`).

    Args:
        recipe: The stages.
        max_steps: Cap every training stage at this many steps (a smoke run); the cap is
            part of each stage's fingerprint, so a later full run starts them again.
        log: Where a line per stage goes.
    """
    if int(os.environ.get("WORLD_SIZE", "1")) > 1:
        # Every process would set stages aside, write their records, soup and export.
        raise ConfigError("a staged recipe runs in one process (its stage records, soups and "
                          "exports are written once): run it on one GPU "
                          "(scripts/train_gpu.sh does), or give several a single-run config")
    with exclusive(recipe.out):
        return _run_recipe(recipe, max_steps, log)


def _run_recipe(recipe: StagedRecipe, max_steps: int | None, log) -> dict:
    prints = recipe.fingerprints()
    if max_steps is not None:
        prints = {k: f"{v}-max{max_steps}" for k, v in prints.items()}
    record_path = recipe.out / "recipe.json"
    record = json.loads(record_path.read_text()) if record_path.is_file() else {}
    record.setdefault("stages", {})
    ran: set[str] = set()
    for stage in recipe.stages:
        if stage.kind == "train" and not ran.intersection(stage.inputs):
            restored = _restore(recipe, stage.name, prints[stage.name], log)
            if restored is not None and restored.get("done"):
                record["stages"][stage.name] = {k: v for k, v in restored.items()
                                                if k != "done"}
                _write_record(record_path, record)
        folder, state = recipe.folder(stage.name), _state(recipe.folder(stage.name))
        same = bool(state and state.get("fingerprint") == prints[stage.name]
                    and not ran.intersection(stage.inputs))
        if same and state.get("done"):
            # Held-out checks do not change the adapter, so a stage trained without one
            # (on a box without Spot) stays done; say so rather than leave it unnoticed.
            unchecked = (stage.kind == "train" and recipe.train_config(stage).eval_pairs
                         and not (folder / "heldout.json").is_file())
            log(f"stage {stage.name}: done, skipped"
                + (" (trained without the held-out check)" if unchecked else ""))
            continue
        # A training stage killed before its first checkpoint has nothing to resume from.
        resume = same and stage.kind == "train" and bool(whole_checkpoints(folder))
        if folder.exists() and not resume:
            # Made with other settings or from other inputs (it would mix two recipes), or
            # cut short before anything in it could be resumed.
            why = _stale(recipe, stage, state, ran, same)
            kept = (_set_aside(recipe, folder)
                    if stage.kind == "train" and _has_training(folder) else None)
            if kept is None:
                shutil.rmtree(folder)
            log(f"stage {stage.name}: {why}; rebuilding it"
                + (f" (the old folder is kept as {kept}; delete it once unneeded)" if kept
                   else ""))
            record["stages"].pop(stage.name, None)
        log(f"stage {stage.name}: {'resumed' if resume else 'started'} ({stage.kind})")
        before = {"wall_s": state.get("wall_s", 0.0), "sessions": state.get("sessions", 0)} \
            if resume else {"wall_s": 0.0, "sessions": 0}
        head = {"name": stage.name, "kind": stage.kind, "inputs": list(stage.inputs),
                "fingerprint": prints[stage.name]}
        _write_state(folder, {**head, **before, "done": False})
        start = time.perf_counter()
        try:
            result = _run_stage(recipe, stage, resume, max_steps)
        except BaseException:
            # An interrupted stage keeps the time it took, which its resumption adds to.
            if folder.exists():
                _write_state(folder, {**head, "done": False, "sessions": before["sessions"] + 1,
                                      "wall_s": round(before["wall_s"] + time.perf_counter()
                                                      - start, 1)})
            raise
        wall = time.perf_counter() - start
        entry = {**head, "wall_s": round(before["wall_s"] + wall, 1),
                 "sessions": before["sessions"] + 1, **_peak_memory(), "result": result}
        _write_state(recipe.folder(stage.name), {**entry, "done": True})
        record["stages"][stage.name] = entry
        ran.add(stage.name)
        _write_record(record_path, record)
        log(f"stage {stage.name}: done in {wall:.0f} s")
    return record
