"""Run an ablation end to end: plan, generate and judge, log, report."""

from __future__ import annotations

from pathlib import Path

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.eval.backends.base import Backend
from ara.eval.harness import AblationConfig, plan, run_job, run_metadata
from ara.eval.report import Results, write_report
from ara.eval.run_store import RunStore
from ara.eval.translator import Translator


def run_ablation(config: AblationConfig, backend: Backend, out: Path, resume: bool = False,
                 progress: bool = True) -> Results:
    """Run (or continue) ``config`` with ``backend`` into ``out`` and write its report.

    Interrupting (Ctrl-C, SIGTERM via the CLI) keeps every finished sample; the
    report is written from whatever is on disk, and ``resume=True`` continues.
    """
    split = load_or_prepare(config.split, config.data_seed)
    meta = run_metadata(config, split, backend.model_id)
    translator = Translator(backend, config.translator)
    jobs = list(plan(config, split))
    with RunStore(out, meta, resume) as store:
        todo = [job for job in jobs if job.key not in store.done]
        bar = tqdm(total=len(jobs), initial=len(jobs) - len(todo), disable=not progress,
                   desc="translating", unit="formula", dynamic_ncols=True)
        valid = 0
        try:
            for i, job in enumerate(todo, 1):
                sample = run_job(translator, job, config.spot_timeout_s)
                store.append(sample)
                valid += sample["valid"]
                bar.set_postfix(variant=job.variant.name, shots=job.shots,
                                valid=f"{100 * valid / i:.0f}%", refresh=False)
                bar.update()
        finally:
            bar.close()
            results = write_report(out)
    return results
