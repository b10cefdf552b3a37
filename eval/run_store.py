"""A run directory: ``run.json`` (what produced it) and ``samples.jsonl`` (append-only).

Each sample is written as one line and fsynced before the next generation starts. A
run killed mid-write leaves at most one partial last line, which :meth:`open` cuts
off before resuming, so no sample is lost or duplicated.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ara.errors import AraError

RUN = "run.json"
SAMPLES = "samples.jsonl"
KEY_FIELDS = ("variant", "shots", "rerun", "uid")


class RunDirError(AraError, ValueError):
    """An output folder that does not fit the run asked for."""


def sample_key(sample: dict) -> tuple:
    return tuple(sample[k] for k in KEY_FIELDS)


def read_samples(folder: Path) -> list[dict]:
    """The complete sample lines of a run (a partial last line is ignored)."""
    path = folder / SAMPLES
    if not path.is_file():
        raise RunDirError(f"no {SAMPLES} in {folder}: not an evaluation run folder")
    samples = []
    for line in path.read_text().splitlines():
        try:
            samples.append(json.loads(line))
        except json.JSONDecodeError:
            break  # only the last line can be partial: an interrupted write
    return samples


class RunStore:
    """The sample log of one run.

    Args:
        folder: The run's output folder.
        meta: What produced the run (:func:`ara.eval.harness.run_metadata`).
        resume: Continue the run in ``folder``; otherwise the folder must hold none.

    Raises:
        RunDirError: If ``folder`` holds a run and ``resume`` is off, or it holds a
            different run than ``meta`` describes.
    """

    def __init__(self, folder: Path, meta: dict, resume: bool) -> None:
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        run_path, samples_path = folder / RUN, folder / SAMPLES
        if run_path.exists() and not resume:
            raise RunDirError(
                f"{folder} already holds a run; pass --resume to continue it, or choose "
                "another --out"
            )
        if resume and run_path.exists():
            _check_same_run(json.loads(run_path.read_text()), meta, folder)
        else:
            run_path.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
        self.done: set[tuple] = set()
        if samples_path.exists():
            self._cut_partial_line(samples_path)
            self.done = {sample_key(s) for s in read_samples(folder)}
        self._fh = open(samples_path, "a", encoding="utf-8")

    @staticmethod
    def _cut_partial_line(path: Path) -> None:
        data = path.read_bytes()
        end = data.rfind(b"\n") + 1
        if end != len(data):
            with open(path, "r+b") as fh:
                fh.truncate(end)

    def append(self, sample: dict) -> None:
        self._fh.write(json.dumps(sample, sort_keys=True) + "\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.done.add(sample_key(sample))

    def close(self) -> None:
        self._fh.close()

    def __enter__(self) -> RunStore:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _check_same_run(old: dict, new: dict, folder: Path) -> None:
    """A resumed run must be the same run: config, model and data version."""
    identity = ("config", "model_id", "data", "grammar_version")
    diffs = [k for k in identity if old.get(k) != new.get(k)]
    if diffs:
        detail = "; ".join(f"{k}: {old.get(k)!r} != {new.get(k)!r}" for k in diffs)
        raise RunDirError(
            f"cannot resume {folder}: it was started with a different {', '.join(diffs)} "
            f"({detail}). Resume with the original flags, or choose another --out"
        )
