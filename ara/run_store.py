"""A run directory: ``run.json`` (what produced it) and ``samples.jsonl`` (append-only).

Each sample is written as one line and fsynced before the next generation starts. A
run killed mid-write leaves at most one partial last line, which opening the store
cuts off before resuming, so no sample is lost or duplicated. Evaluation runs store
one sample per (variant, shots, rerun, uid); Experiment 2 stores its trials' rows the
same way (``trials.jsonl``, keyed by trial and method, whole trials only).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from pathlib import Path

from ara.errors import AraError
from ara.provenance import write_atomic

RUN = "run.json"
SAMPLES = "samples.jsonl"
KEY_FIELDS = ("variant", "shots", "rerun", "uid")
#: The fields of run.json that make two runs the same run.
IDENTITY = ("config", "model_id", "data", "grammar_version")


class RunDirError(AraError, ValueError):
    """An output folder that does not fit the run asked for."""


def sample_key(sample: dict) -> tuple:
    return tuple(sample[k] for k in KEY_FIELDS)


def cut_partial_line(path: Path) -> None:
    """Drop the last line of an append-only JSON Lines file where an interrupted write
    left it without its newline (only the last can be), so that appending goes on from a
    whole line."""
    data = path.read_bytes()
    end = data.rfind(b"\n") + 1
    if end != len(data):
        with open(path, "r+b") as fh:
            fh.truncate(end)


def read_samples(folder: Path, samples: str = SAMPLES) -> list[dict]:
    """The complete sample lines of a run (a partial last line is ignored)."""
    path = folder / samples
    if not path.is_file():
        raise RunDirError(f"no {samples} in {folder}: not an evaluation run folder")
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
        samples: The log's file name.
        key: A sample's identity; a resumed run skips the keys in :attr:`done`.
        identity: The fields of ``meta`` a resumed run must share with the saved one.
        keep: Which saved samples a resumed run keeps (all by default); the log is
            rewritten without the others, e.g. the rows of an unfinished trial.

    Raises:
        RunDirError: If ``folder`` holds a run and ``resume`` is off, or it holds a
            different run than ``meta`` describes.
    """

    def __init__(self, folder: Path, meta: dict, resume: bool, *, samples: str = SAMPLES,
                 key: Callable[[dict], tuple] = sample_key, identity: Sequence[str] = IDENTITY,
                 keep: Callable[[list[dict]], list[dict]] | None = None) -> None:
        self.folder, self.key = folder, key
        folder.mkdir(parents=True, exist_ok=True)
        run_path, samples_path = folder / RUN, folder / samples
        if run_path.exists() and not resume:
            raise RunDirError(
                f"{folder} already holds a run; pass --resume to continue it, or choose "
                "another --out"
            )
        if resume and run_path.exists():
            _check_same_run(json.loads(run_path.read_text()), meta, folder, identity)
        else:
            run_path.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
        self.done: set[tuple] = set()
        if samples_path.exists():
            cut_partial_line(samples_path)
            saved = read_samples(folder, samples)
            if keep is not None and len(kept := keep(saved)) != len(saved):
                _rewrite(samples_path, kept)
                saved = kept
            self.done = {key(s) for s in saved}
        self._fh = open(samples_path, "a", encoding="utf-8")

    def append(self, *samples: dict) -> None:
        """Write ``samples`` (one line each) and make them durable together."""
        for sample in samples:
            self._fh.write(json.dumps(sample, sort_keys=True) + "\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.done.update(self.key(s) for s in samples)

    def close(self) -> None:
        self._fh.close()

    def __enter__(self) -> RunStore:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _rewrite(path: Path, samples: list[dict]) -> None:
    """Replace the log atomically: an interruption leaves the old one or the new one."""
    write_atomic(path, "".join(json.dumps(s, sort_keys=True) + "\n" for s in samples))


def _check_same_run(old: dict, new: dict, folder: Path, identity: Sequence[str]) -> None:
    """A resumed run must be the same run: config, model and data version."""
    diffs = [k for k in identity if old.get(k) != new.get(k)]
    if diffs:
        detail = "; ".join(f"{k}: {old.get(k)!r} != {new.get(k)!r}" for k in diffs)
        raise RunDirError(
            f"cannot resume {folder}: it was started with a different {', '.join(diffs)} "
            f"({detail}). Resume with the original flags, or choose another --out"
        )
