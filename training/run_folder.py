"""What a training run's folder holds, read back: its whole checkpoints, whether a
resumed config may go on with it, where its warm start came from, and the summary of
its log. The recipe writes the folder (``training/recipe.py``)."""

from __future__ import annotations

import fcntl
import json
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ara.errors import ConfigError
from ara.provenance import differing, sha256_file
from ara.training.config import BOOKKEEPING, TrainConfig


@contextmanager
def exclusive(out: Path) -> Iterator[None]:
    """Hold ``out`` for one ``ara train`` at a time: a second one on the same folder (a
    rerun started while the first still trains) would write the same checkpoints, or
    set the live folder aside. Only the first process of a multi-process run holds it."""
    if int(os.environ.get("RANK", "0")) != 0:
        yield
        return
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / ".lock", "w") as handle:
        # `--status` holds the lock for an instant to see whether a run holds it: a run
        # starting in that instant tries again rather than refuse.
        for attempt in range(5):
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if attempt == 4:
                    raise ConfigError(f"another ara train is running on {out}: wait for it, "
                                      "or stop it first") from None
                time.sleep(0.1)
        yield


def held(out: Path) -> bool:
    """Whether an ``ara train`` holds ``out`` now (see :func:`exclusive`)."""
    lock = Path(out) / ".lock"
    if not lock.is_file():
        return False
    with open(lock) as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(handle, fcntl.LOCK_UN)
        return False


def checkpoint_folder(out: Path, step: int) -> Path:
    """Where run folder ``out`` keeps its checkpoint of ``step``."""
    return out / "checkpoints" / f"step_{step}"


def checkpoint_step(checkpoint: Path) -> int:
    """The step a :func:`checkpoint_folder` was saved at."""
    return int(checkpoint.name.removeprefix("step_"))


def whole_checkpoints(out: Path) -> list[Path]:
    """The whole checkpoints of run folder ``out`` (``step.json`` is written last, so a
    checkpoint a kill cut short has none), oldest first."""
    return sorted((p for p in (out / "checkpoints").glob("step_*")
                   if p.joinpath("step.json").is_file()), key=checkpoint_step)


#: Settings a resumed run may change: how long it runs (``--max-steps`` extends a run),
#: the precision it computes in (a run may go on on another machine, as a run begun on
#: a GPU goes on on a CPU), and those that leave the adapter as it is.
RESUMABLE_KEYS = BOOKKEEPING | {"max_steps", "precision"}


def refuse_changed_config(run_json: Path, config: TrainConfig) -> None:
    """A resumed run continues the same training: the same data, schedule and model.
    The data version is compared as loaded (:func:`refuse_changed_data`), not as written: pinning
    the version a run started on unpinned is no change."""
    started, now = json.loads(run_json.read_text())["config"], config.to_dict()
    started["data"] = {**started["data"], "version": None}
    now["data"] = {**now["data"], "version": None}
    changed = {k: values for k, values in differing(started, now).items()
               if k not in RESUMABLE_KEYS}
    if changed:
        detail = ", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in changed.items())
        may = ", ".join(sorted(RESUMABLE_KEYS))
        raise ConfigError(
            f"--resume: the config differs from the one {run_json.parent} was started with "
            f"({detail}); resume with the same config (only {may} may change), or train "
            "into another out folder")


def refuse_changed_data(run_json: Path, data, loaded: str) -> None:
    """A resumed run goes on with the data it started on: the version this release loads
    for its config (``data``) and the user's pairs file as they were."""
    started = json.loads(run_json.read_text())["data"]
    if started["version"] != loaded:
        raise ConfigError(
            f"--resume: {run_json.parent} was started on {data.split} version "
            f"{started['version']}, but this release loads {loaded}; pin data.version: "
            f"{started['version']} in the config")
    if data.pairs and started.get("pairs_sha256") != sha256_file(data.pairs):
        raise ConfigError(f"--resume: {data.pairs} changed since {run_json.parent} started; "
                          "train the new pairs into another out folder")


def adapter_identity(folder: str | Path | None) -> dict | None:
    """Where a warm start came from: the folder and its weights' hash."""
    if not folder:
        return None
    weights = sorted(Path(folder).glob("adapter_model.*"))
    digest = sha256_file(weights[0]) if weights else None
    return {"path": str(folder), "sha256": digest}


def log_rows(path: Path) -> list[dict]:
    """The lines of a ``train_log.jsonl`` (none where it is missing), over every session
    of the run, without the half-written line of a session killed mid-write."""
    rows = []
    for line in path.read_text().splitlines() if path.is_file() else ():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return rows


def log_summary(path: Path) -> dict:
    """The first and last loss and the seconds spent in steps, over every session of the run: a
    session killed outright records no wall time of its own, but its steps are logged
    (a step redone after a resume counts again, as the time was spent)."""
    rows = log_rows(path)
    return {"first_loss": rows[0]["loss"] if rows else None,
            "last_loss": rows[-1]["loss"] if rows else None,
            "step_seconds": round(sum(r["seconds"] for r in rows), 1)}
