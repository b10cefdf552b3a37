"""Running a staged recipe (:mod:`ara.training.stages`): each stage not done, in order.

A rerun skips done stages, resumes an interrupted training stage from its newest
checkpoint, and runs again, from scratch, a stage whose settings or inputs changed, so
that every stage after an edited one is rebuilt too; a rebuilt training stage's old
folder is set aside in ``OUT/replaced/`` and brought back when its settings return.
``OUT/recipe.json`` records each stage's wall time and memory.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from ara.errors import ConfigError
from ara.provenance import write_atomic
from ara.training.config import TrainConfig
from ara.training.export import PARITY_PAIRS, export_checked
from ara.training.run_folder import checkpoint_step, exclusive, held, log_rows, whole_checkpoints
from ara.training.stages import REPLACED, Stage, StagedRecipe


def _state(folder: Path) -> dict | None:
    """A stage folder's record; ``None`` where it has none (or one a crash left unread-
    able: the stage is then rebuilt, its folder set aside)."""
    path = folder / "stage.json"
    try:
        return json.loads(path.read_text()) if path.is_file() else None
    except json.JSONDecodeError:
        return None


def _write_json(path: Path, data: dict) -> None:
    write_atomic(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def _write_state(folder: Path, state: dict) -> None:
    _write_json(folder / "stage.json", state)


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


def _make_room(recipe: StagedRecipe, folder: Path, kind: str) -> Path | None:
    """Clear a stage's folder for another: one that holds training is set aside (where
    it went is returned), anything else removed."""
    if kind == "train" and _has_training(folder):
        return _set_aside(recipe, folder)
    shutil.rmtree(folder)
    return None


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


def _restore(recipe: StagedRecipe, name: str, old: Path, log) -> None:
    """Bring back ``old``, a folder of stage ``name`` set aside with the settings asked
    for now (an edit undone, a data version pinned again), setting aside what stands in
    its place."""
    folder = recipe.folder(name)
    kept = _make_room(recipe, folder, "train") if folder.exists() else None
    shutil.move(str(old), str(folder))
    log(f"stage {name}: brought back from {old} (made with these settings)"
        + (f"; the folder in its place is kept as {kept}" if kept else ""))


@dataclass(frozen=True)
class _Plan:
    """What a run of the recipe does with one stage, decided from the folders alone
    (:func:`run_recipe` acts on it, :func:`recipe_status` tells it).

    Attributes:
        folder: Where the stage's record and checkpoints are: its own folder, or the one
            set aside in ``replaced/`` that is brought back (``restore``).
        state: That folder's stage record.
        done: Skipped: made with these settings from these inputs.
        resume: Trained on from the newest of ``checkpoints``.
        waits: Inputs that run first in this run (so the stage runs after them).
        why: Why its own folder cannot be kept, where it runs again.
    """

    folder: Path
    state: dict | None
    restore: bool
    done: bool
    resume: bool
    checkpoints: tuple[Path, ...]
    waits: tuple[str, ...]
    why: str | None


def _plan(recipe: StagedRecipe, stage: Stage, fingerprint: str, runs: set[str]) -> _Plan:
    """``runs``: the stages before this one that this run trains, soups or exports."""
    own = recipe.folder(stage.name)
    waits = tuple(name for name in stage.inputs if name in runs)
    found = (_set_aside_match(recipe, stage.name, fingerprint)
             if stage.kind == "train" and not waits else None)
    folder, state = found if found is not None else (own, _state(own))
    same = bool(state and state.get("fingerprint") == fingerprint and not waits)
    done = same and bool(state.get("done"))
    # A training stage killed before its first checkpoint has nothing to resume from.
    checkpoints = tuple(whole_checkpoints(folder)) if same and stage.kind == "train" else ()
    resume = not done and bool(checkpoints)
    why = (_stale(recipe, stage, state, set(waits), same)
           if not done and not resume and own.exists() else None)
    return _Plan(folder, state, found is not None, done, resume, checkpoints, waits, why)


def _unchecked(recipe: StagedRecipe, stage: Stage, folder: Path) -> bool:
    """A done training stage trained without the held-out check its config asks for:
    checks do not change the adapter, so it stays done (on a box without Spot, say)."""
    return bool(stage.kind == "train" and recipe.train_config(stage).eval_pairs
                and not (folder / "heldout.json").is_file())


def _set_aside_match(recipe: StagedRecipe, name: str,
                     fingerprint: str) -> tuple[Path, dict] | None:
    """The newest folder of stage ``name`` set aside with ``fingerprint``, done or
    resumable, and its record; ``None`` where the stage's own folder has it already."""
    if (_state(recipe.folder(name)) or {}).get("fingerprint") == fingerprint:
        return None
    for old in sorted((recipe.out / REPLACED).glob(f"{name}-*"), reverse=True):
        state = _state(old)
        if state and state.get("name") == name and state.get("fingerprint") == fingerprint \
                and (state.get("done") or whole_checkpoints(old)):
            return old, state
    return None


def _train_config(recipe: StagedRecipe, stage: Stage, max_steps: int | None) -> TrainConfig:
    """A training stage's run, capped at ``max_steps`` (``--max-steps``) where given."""
    config = recipe.train_config(stage)
    if max_steps is None:
        return config
    capped = min(config.max_steps or max_steps, max_steps)
    return TrainConfig.from_dict({**config.to_dict(), "max_steps": capped})


def _run_stage(recipe: StagedRecipe, stage: Stage, resume: bool,
               max_steps: int | None) -> dict:
    folder = recipe.folder(stage.name)
    if stage.kind == "train":
        from ara.training.recipe import run_training

        return run_training(_train_config(recipe, stage, max_steps), resume)
    if stage.kind == "soup":
        from ara.training.soup import soup_runs

        record = soup_runs([recipe.folder(name) for name in stage.inputs],
                           stage.settings.get("weights"), folder, stage.settings.get("rank"))
        return {k: record[k] for k in ("soup", "reduced") if k in record}
    source = recipe.folder(stage.inputs[0])
    manifest = export_checked(source, ("f16",), lora_gguf=True,
                              parity_pairs=stage.settings.get("parity", PARITY_PAIRS))
    # The export lives in its own stage folder, so that rerunning it leaves the
    # adapter it read alone.
    if folder.exists():
        shutil.rmtree(folder)
    shutil.move(str(source / "export"), str(folder))
    # With the record of the run it exports, the folder is all that shipping needs; its
    # adapter stays beside it for a warm start from the candidate (`init_adapter`).
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
    prints = recipe.fingerprints(max_steps)
    record_path = recipe.out / "recipe.json"
    record = json.loads(record_path.read_text()) if record_path.is_file() else {}
    record.setdefault("stages", {})
    ran: set[str] = set()
    for stage in recipe.stages:
        plan = _plan(recipe, stage, prints[stage.name], ran)
        folder = recipe.folder(stage.name)
        if plan.restore:
            _restore(recipe, stage.name, plan.folder, log)
            if plan.done:
                record["stages"][stage.name] = {k: v for k, v in plan.state.items()
                                                if k != "done"}
                _write_json(record_path, record)
        state, resume = plan.state, plan.resume
        if plan.done:
            log(f"stage {stage.name}: done, skipped"
                + (" (trained without the held-out check)"
                   if _unchecked(recipe, stage, folder) else ""))
            continue
        if plan.why is not None:
            # Made with other settings or from other inputs (it would mix two recipes), or
            # cut short before anything in it could be resumed.
            kept = _make_room(recipe, folder, stage.kind)
            log(f"stage {stage.name}: {plan.why}; rebuilding it"
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
        _write_json(record_path, record)
        log(f"stage {stage.name}: done in {wall:.0f} s")
    return record


def recipe_status(recipe: StagedRecipe, max_steps: int | None = None) -> dict:
    """Where a recipe stands, read from its folder without changing anything: what a
    rerun (with ``max_steps``, as ``--max-steps``) would do with each stage, by the
    rules it would follow (:func:`_plan`), each training stage's steps, and the
    training steps left at the pace its logs show."""
    prints = recipe.fingerprints(max_steps)
    running = held(recipe.out)
    runs: set[str] = set()  # the stages a rerun would run
    rows, seconds = [], []
    for stage in recipe.stages:
        plan = _plan(recipe, stage, prints[stage.name], runs)
        kept = checkpoint_step(plan.checkpoints[-1]) if plan.checkpoints else 0
        # The run holding the folder is at the first stage not done (if it runs these
        # settings: a config edited since would show the stage as stale).
        live = (running and not plan.done and not runs
                and (plan.state or {}).get("fingerprint") == prints[stage.name])
        if plan.done:
            says = "done" + (" (trained without the held-out check)"
                             if _unchecked(recipe, stage, plan.folder) else "")
        elif live:
            says = "running now" + (f" (checkpoint at step {kept})" if plan.resume else "")
        elif plan.resume:
            says = f"resumes from step {kept}"
        elif plan.waits:
            says = (f"runs {'again ' if recipe.folder(stage.name).exists() else ''}after "
                    f"{', '.join(plan.waits)}")
        elif plan.why:
            says = f"runs again: {plan.why}"
        else:
            says = "to run"
        if plan.restore:
            says += f" (brought back from {plan.folder.name})"
        row = {"name": stage.name, "kind": stage.kind, "state": says, "steps_done": None,
               "steps_total": None, "steps_left": None}
        if stage.kind == "train":
            config = _train_config(recipe, stage, max_steps)
            mine = plan.done or plan.resume or live  # its folder is this stage's
            total = _total_steps(plan.folder / "run.json", config) if mine else (
                config.max_steps)
            logged = log_rows(plan.folder / "train_log.jsonl") if mine else []
            seconds += [r["seconds"] for r in logged]
            # Steps kept: the newest checkpoint's (a rerun redoes those after it), or,
            # while this stage trains, the steps logged so far.
            steps = total if plan.done else kept
            if live and logged:
                steps = max(steps, logged[-1]["step"])
            row.update(steps_done=steps, steps_total=total,
                       steps_left=None if total is None else total - steps)
        if not plan.done:
            runs.add(stage.name)
        rows.append(row)
    pace = statistics.median(seconds[-200:]) if seconds else None
    left = [r["steps_left"] for r in rows if r["kind"] == "train"]
    known = sum(n for n in left if n is not None)
    return {"out": str(recipe.out), "running": running, "stages": rows,
            "seconds_per_step": pace, "steps_left": known,
            "steps_left_unknown": any(n is None for n in left),
            "hours_left": None if pace is None else round(known * pace / 3600, 2)}


def _total_steps(run_json: Path, config: TrainConfig) -> int | None:
    """A started run's steps, from the training records its ``run.json`` counted
    (``max_steps`` alone where it has none yet)."""
    try:
        examples = json.loads(run_json.read_text())["data"]["train_examples"]
    except (OSError, ValueError, KeyError):
        return config.max_steps
    return config.steps_for(examples)
