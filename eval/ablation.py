"""Run an ablation end to end: plan, generate and judge, log, report."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.errors import ConfigError
from ara.eval.harness import (
    FILE_SPLIT,
    AblationConfig,
    Split,
    plan,
    run_metadata,
    sample_of,
    translate_job,
)
from ara.eval.report import Results, write_report
from ara.eval.translate.backends.base import Backend
from ara.eval.translate.translator import Translator
from ara.eval.user_data import file_split
from ara.run_store import RunStore


def load_data(config: AblationConfig) -> Split:
    """The run's data: a registered split (prepared on first use) or the user's files."""
    if config.split == FILE_SPLIT:
        assert config.data is not None  # the config insists
        examples = None if config.examples is None else Path(config.examples)
        return file_split(Path(config.data), examples, config.translator)
    return load_or_prepare(config.split, config.data_seed)


def run_ablation(config: AblationConfig, backend: Backend, out: Path, resume: bool = False,
                 progress: bool = True, concurrency: int = 1,
                 split: Split | None = None) -> Results:
    """Run (or continue) ``config`` with ``backend`` into ``out`` and write its report.

    Interrupting (Ctrl-C, SIGTERM via the CLI) keeps every finished sample; the
    report is written from whatever is on disk, and ``resume=True`` continues.

    With ``concurrency`` > 1 (remote backends only: the server batches the requests)
    that many generations are in flight at once; samples are still judged and written
    one at a time in the planned order, so the log, resume and the no-duplicate rule
    are those of a serial run.

    ``split`` is the run's data if the caller already read it (:func:`load_data`),
    e.g. to refuse a bad file before loading the model.
    """
    if concurrency < 1:
        raise ConfigError(f"--concurrency must be >= 1, got {concurrency}")
    if concurrency > 1 and not backend.concurrent:
        raise ConfigError("--concurrency > 1 needs a remote backend (--model http://...): a "
                          "local model generates one answer at a time")
    split = load_data(config) if split is None else split
    meta = run_metadata(config, split, backend.model_id)
    translator = Translator(backend, config.translator)
    jobs = list(plan(config, split))
    with RunStore(out, meta, resume) as store:
        todo = [job for job in jobs if job.key not in store.done]
        bar = tqdm(total=len(jobs), initial=len(jobs) - len(todo), disable=not progress,
                   desc="translating", unit="formula", dynamic_ncols=True)
        valid = 0
        pool = ThreadPoolExecutor(concurrency) if concurrency > 1 else None
        try:
            if pool is None:
                answers = (translate_job(translator, job, config) for job in todo)
            else:  # in the planned order, whatever order they finish in
                answers = pool.map(lambda job: translate_job(translator, job, config), todo)
            for i, (job, answer) in enumerate(zip(todo, answers, strict=True), 1):
                sample = sample_of(job, answer, config.spot_timeout_s)
                store.append(sample)
                valid += sample["valid"]
                bar.set_postfix(variant=job.variant.name, shots=job.shots,
                                valid=f"{100 * valid / i:.0f}%", refresh=False)
                bar.update()
        finally:
            if pool is not None:  # answers in flight are dropped, and asked again on resume
                pool.shutdown(wait=False, cancel_futures=True)
            bar.close()
            results = write_report(out)
    return results
