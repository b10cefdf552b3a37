"""The F/P/C ablation of the paper's Experiment 1, resumable.

Variants are named by their letters joined with ``+``: F (few-shot examples), P (the
grammar in the prompt), C (grammar-constrained decoding); ``F+P+C`` uses all three.
Variants without F run zero-shot, once per rerun. Each rerun redraws the few-shot
examples (seeded); all variants of a run see the same examples and the same test
pairs. Every generation is appended to ``samples.jsonl`` as soon as it is judged, so
an interrupted run loses nothing, and ``--resume`` skips exactly the samples on disk.
"""

from __future__ import annotations

import os
import platform
import random
from collections import Counter
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Protocol

from ara import __version__
from ara.data import Record
from ara.data.mixture import sentence_key
from ara.data.store import FORMS, SPLITS
from ara.errors import ConfigError, did_you_mean, refuse_unknown_keys
from ara.eval.translate.answering import Answer
from ara.eval.translate.prompt import Shot, sample_shots
from ara.eval.translate.repair import RepairConfig, translate_repaired
from ara.eval.translate.request_file import FILE_SPLIT
from ara.eval.translate.similar import EXAMPLES_BY, index_for
from ara.eval.translate.translator import Translator, TranslatorConfig
from ara.grammars import GRAMMAR_VERSION
from ara.grammars.spot_bridge import judge
from ara.provenance import git_commit

LETTERS = {"F": "few_shot", "P": "grammar_in_prompt", "C": "constrained"}


class Split(Protocol):
    """What a run reads of its data: a prepared split
    (:class:`~ara.data.store.PreparedSplit`), or a user's file read as one
    (:class:`~ara.eval.user_data.FileSplit`)."""

    @property
    def version(self) -> str: ...

    @property
    def manifest(self) -> dict: ...

    def records(self, part: str, form: str | None = None) -> list[Record]: ...


@dataclass(frozen=True)
class Variant:
    """One ablation variant, e.g. ``F+P+C``."""

    name: str
    few_shot: bool
    grammar_in_prompt: bool
    constrained: bool

    @classmethod
    def parse(cls, name: str) -> Variant:
        if name.strip().lower() == "none":  # zero-shot, no grammar: a fine-tune's own prompt
            return cls("none", False, False, False)
        letters = name.strip().upper().split("+")
        unknown = [x for x in letters if x not in LETTERS]
        if unknown or len(set(letters)) != len(letters) or not name.strip():
            raise ConfigError(
                f"variant {name!r}: use the letters F (few-shot), P (grammar in prompt), C "
                "(constrained decoding) joined with '+', each once, e.g. F+P+C; or none"
            )
        canonical = "+".join(x for x in "FPC" if x in letters)
        return cls(canonical, **{LETTERS[x]: x in letters for x in LETTERS})


#: Most worked examples one prompt shows (20-shot prompts are about 1,000 tokens).
MAX_SHOTS = 50


@dataclass(frozen=True)
class AblationConfig:
    """One ablation run.

    Args:
        split: Prepared split (``paper``, ``disjoint``, ``timed``, ``compositional``,
            or a hand-written suite of :data:`ara.data.handwritten.SUITES`), or
            ``file``: the pairs of ``data``.
        form: ``lifted`` or ``grounded`` records; for ``file``, None (every line) or
            the lines of that form.
        data: With ``split="file"``: a JSON Lines file of the user's pairs
            (:mod:`ara.eval.user_data`), every line with its reference.
        examples: With ``split="file"``: a file of pairs in the same format to draw
            worked examples from (None: the compositional train side, in the tests'
            form).
        variants: Variant names, e.g. ``("F", "F+P", "F+P+C")``.
        shots: Few-shot counts for the F variants, 0 to 50 (0: F runs zero-shot;
            variants without F always do).
        reruns: Reruns, each with freshly drawn examples.
        limit: Test pairs, sampled once with ``seed``.
        seed: Seeds the test sample and every rerun's examples.
        data_seed: Seed the split was prepared with.
        model: What ``--model`` named (recorded; the backend reports its hash).
        spot_timeout_s: Time limit per Spot check; past it the pair counts as undecided.
        translator: Grammar and budget settings.
        repair: With C: when the greedy answer has a gap, look for one with fewer
            (:func:`~ara.eval.translate.repair.translate_repaired`); ``samples`` 0 (the
            paper's variants): greedy only. Saved as ``repair``, ``repair_by`` and
            ``repair_doubt``, and only when on, as runs from before repair wrote none;
            runs repaired before ``by`` or ``doubt`` existed read as ``samples`` and 0.
        examples_by: How the F variants' worked examples are chosen: ``random`` (drawn
            with the seed, the same for every test pair of a rerun) or ``similar`` (for
            each test pair, the pool's pairs most like it, :mod:`ara.eval.translate.similar`,
            never one that says the test's own sentence).
    """

    split: str = "paper"
    form: str | None = "lifted"
    variants: tuple[str, ...] = ("F", "F+P", "F+P+C")
    shots: tuple[int, ...] = (5, 20)
    reruns: int = 3
    limit: int = 1000
    seed: int = 0
    data_seed: int = 0
    model: str = "default"
    spot_timeout_s: float = 10.0
    translator: TranslatorConfig = field(default_factory=TranslatorConfig)
    repair: RepairConfig = RepairConfig(samples=0)
    data: str | None = None
    examples: str | None = None
    examples_by: str = "random"

    def __post_init__(self) -> None:
        if self.split == FILE_SPLIT:
            if self.data is None:
                raise ConfigError("split 'file' reads the pairs of data: name the file")
        elif self.split not in SPLITS:
            raise ConfigError(f"unknown split {self.split!r}. {did_you_mean(self.split, SPLITS)}")
        elif self.data is not None or self.examples is not None:
            raise ConfigError(f"data and examples are files of one's own pairs, for split "
                              f"'file'; split {self.split!r} has its own")
        if not (self.form in FORMS or self.form is None and self.split == FILE_SPLIT):
            raise ConfigError(f"unknown form {self.form!r}. {did_you_mean(str(self.form), FORMS)}")
        object.__setattr__(self, "variants", tuple(Variant.parse(v).name for v in self.variants))
        if self.split == "timed" and not self.translator.intervals:
            # NL2TL's timed formulas carry intervals: a grammar without them could not
            # express a single reference.
            object.__setattr__(self, "translator", replace(self.translator, intervals=True))
        if not self.variants:
            raise ConfigError("variants: name at least one, e.g. C or none,C,F+C")
        if not self.shots or any(not 0 <= k <= MAX_SHOTS for k in self.shots):
            raise ConfigError(f"shots: counts from 0 to {MAX_SHOTS}, got {self.shots}")
        if self.reruns < 1:
            raise ConfigError(f"reruns: at least 1, got {self.reruns}")
        if self.limit < 1:
            raise ConfigError(f"limit: at least 1 test pair, got {self.limit}")
        if not self.spot_timeout_s > 0:
            raise ConfigError(f"spot_timeout_s: seconds per Spot check, > 0; got "
                              f"{self.spot_timeout_s}")
        if self.repair.samples is None:  # an ablation states its repair: none by default
            raise ConfigError("repair.samples: name the answers to draw, 0 to 32 (0: off)")
        if self.examples_by not in EXAMPLES_BY:
            raise ConfigError(f"examples by {self.examples_by!r}? choose one of "
                              f"{', '.join(EXAMPLES_BY)}")

    def to_dict(self) -> dict:
        data = asdict(self)
        data["variants"], data["shots"] = list(self.variants), list(self.shots)
        del data["repair"]  # saved flat, as runs wrote it before it was one config
        if self.repair.samples:  # and not at all without repair: older runs resume
            data |= {"repair": self.repair.samples, "repair_by": self.repair.by,
                     "repair_doubt": self.repair.doubt}
        if self.split != FILE_SPLIT:  # the same for runs from before files could be read
            del data["data"], data["examples"]
        if self.examples_by == "random":  # and before examples could be chosen by similarity
            del data["examples_by"]
        return data

    @classmethod
    def from_dict(cls, data: dict) -> AblationConfig:
        refuse_unknown_keys(data, {f.name for f in fields(cls)} | {"repair_by", "repair_doubt"})
        data = dict(data)
        # Runs repaired before repair by edits, or of doubted answers, existed say so.
        by, doubt = data.pop("repair_by", "samples"), data.pop("repair_doubt", 0.0)
        repair = data.get("repair", 0)
        data["repair"] = RepairConfig(repair, by, doubt) if repair else RepairConfig(samples=0)
        data["variants"], data["shots"] = tuple(data["variants"]), tuple(data["shots"])
        data["translator"] = TranslatorConfig(**data.get("translator", {}))
        return cls(**data)


@dataclass(frozen=True)
class Job:
    """One generation to do."""

    rerun: int
    shots: int
    variant: Variant
    record: Record
    examples: tuple[Shot, ...]

    @property
    def key(self) -> tuple[str, int, int, str]:
        return (self.variant.name, self.shots, self.rerun, self.record.uid)


def test_sample(config: AblationConfig, split: Split) -> list[Record]:
    """The test pairs of the run: ``limit`` records drawn with ``seed``."""
    records = split.records("test", config.form)
    if not records and config.split == FILE_SPLIT:
        raise ConfigError(f"{config.data} has no {config.form} lines (--form {config.form}); "
                          "a line is lifted when its propositions are all prop_<n>")
    if not records:
        raise ConfigError(f"split {config.split} has no {config.form} test records")
    if config.limit >= len(records):
        return records
    return random.Random(config.seed).sample(records, config.limit)


def shot_pool(config: AblationConfig, split: Split) -> list[Record]:
    """Where worked examples come from: the split's own train side, or for a test-only
    split (the hand-written suites, a user's file without examples) the compositional
    train side, which holds none of the suites' sentences, in the tests' form (the
    form most of a user's lines have)."""
    pool = split.records("train", config.form)
    if pool or not any(v.few_shot for v in map(Variant.parse, config.variants)):
        return pool
    from ara.data import load_or_prepare

    forms = Counter(r.form for r in split.records("test", config.form))
    form = config.form or max(FORMS, key=lambda f: forms[f])
    pool = load_or_prepare("compositional", config.data_seed).records("train", form)
    tests = {sentence_key(r.nl) for r in split.records("test")}  # "Go." is the test "go"
    return [r for r in pool if sentence_key(r.nl) not in tests]


def plan(config: AblationConfig, split: Split) -> Iterator[Job]:
    """Every generation of the run, grouped so that consecutive prompts share a prefix.

    The data is checked when this is called, not when the jobs are iterated, so a
    caller can refuse a run before loading a model.

    Raises:
        ConfigError: If there is nothing to test, or fewer worked examples to draw
            from than ``shots`` asks for.
    """
    tests = test_sample(config, split)
    pool = shot_pool(config, split)
    variants = [Variant.parse(v) for v in config.variants]
    asked = max(config.shots) if any(v.few_shot for v in variants) else 0
    if asked > len(pool):
        raise ConfigError(f"{asked} worked examples asked for (--shots), but only "
                          f"{len(pool)} to draw them from")
    return _jobs(config, tests, pool, variants)


def _jobs(config: AblationConfig, tests: list[Record], pool: list[Record],
          variants: list[Variant]) -> Iterator[Job]:
    for rerun in range(config.reruns):
        groups = [(k, [v for v in variants if v.few_shot]) for k in config.shots]
        groups.append((0, [v for v in variants if not v.few_shot]))
        for shots, group in groups:
            if not group:
                continue
            rng = random.Random(f"{config.seed}:{rerun}:{shots}")
            examples = tuple(sample_shots(pool, shots, rng)) if shots else ()
            similar = index_for(pool) if shots and config.examples_by == "similar" else None
            for variant in group:
                for record in tests:
                    if similar is not None and variant.few_shot:
                        examples = tuple(map(Shot.of, similar.nearest(
                            record.nl, record.aps, shots, other_sentences=True)))
                    yield Job(rerun, shots, variant, record, examples)


def translate_job(translator: Translator, job: Job, config: AblationConfig) -> Answer:
    """The generation of one job (what may run concurrently against a server), repaired
    as ``config`` says; neither scored nor checked for gaps, which a run does not report."""
    r = job.record
    if config.repair.samples and job.variant.constrained:
        vote = translate_repaired(translator, r.nl, r.aps, job.examples, config.repair,
                                  grammar_in_prompt=job.variant.grammar_in_prompt)
        return Answer(vote.result, translator.backend.model_id, vote)
    return Answer(translator.translate(r.nl, r.aps, job.examples,
                                       job.variant.grammar_in_prompt, job.variant.constrained),
                  translator.backend.model_id)


def sample_of(job: Job, answer: Answer, timeout_s: float) -> dict:
    """One line of samples.jsonl: the job, its translation and Spot's verdicts."""
    r, result = job.record, answer.result
    return {
        "variant": job.variant.name, "shots": job.shots, "rerun": job.rerun, "uid": r.uid,
        "nl": r.nl, "aps": list(r.aps), "reference": r.stl, "raw": result.raw,
        "stl": result.stl, "valid": result.valid, "error": result.error,
        **judge(r.stl, result.stl, timeout_s),
        "ms": round(answer.ms, 2), "attempts": answer.attempts,
        "prompt_tokens": result.prompt_tokens,
        "completion_tokens": result.completion_tokens, "cached_tokens": result.cached_tokens,
        "stop": result.stop, "masked_steps": result.masked_steps,
        "prompt_sha256": result.prompt_sha256,
    }


def run_metadata(config: AblationConfig, split: Split, model_id: str) -> dict:
    """What produced the run: config, model, data, grammar, code and machine."""
    return {
        "config": config.to_dict(),
        "model_id": model_id,
        "data": {"split": config.split, "version": split.version,
                 "manifest_version": split.manifest["version"]},
        "grammar_version": GRAMMAR_VERSION,
        "seed": config.seed,
        **({"data_files": split.manifest["files"]} if config.split == FILE_SPLIT else {}),
        "ara_version": __version__,
        "git_commit": git_commit(),
        "machine": {"platform": platform.platform(), "processor": platform.machine(),
                    "cpus": os.cpu_count()},
    }
