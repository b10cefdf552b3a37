"""Typed configuration of a LoRA fine-tuning run, loaded from YAML.

Each YAML section goes straight into its dataclass, so a misspelt key raises with
the list of known ones instead of being ignored.
"""

from __future__ import annotations

import json
import re
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import yaml

from ara.errors import ConfigError, refuse_unknown_keys
from ara.eval.translate.models import FINETUNED_LORA


def read_config(path: str | Path) -> dict:
    """A config file's settings: a YAML mapping, or a ConfigError that says what is wrong."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"config file not found: {path}")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ConfigError(f"{path} is not a UTF-8 text file") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ConfigError(f"{path} is not valid YAML{where}: "
                          f"{getattr(err, 'problem', None) or err}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path} must be a YAML mapping of settings (key: value), "
                          f"not a {type(data).__name__}")
    return data


def _number(name: str, value, low: float, *, whole: bool = False, below: float | None = None,
            none: bool = False, strict: bool = False) -> None:
    """Refuse a setting that is not a number in range, by name: YAML reads ``2e-4`` as
    text and ``true`` as a number, which would otherwise fail far from the config."""
    if value is None and none:
        return
    kinds = int if whole else (int, float)
    if (not isinstance(value, kinds) or isinstance(value, bool) or value < low
            or (strict and value == low) or (below is not None and value >= below)):
        wanted = f"a {'whole ' if whole else ''}number {'>' if strict else '>='} {low:g}"
        wanted += f" and < {below:g}" if below is not None else ""
        wanted += " (or null)" if none else ""
        hint = (" (YAML reads 2e-4 as text: write 2.0e-4)"
                if isinstance(value, str) and "e" in value.lower() else "")
        raise ConfigError(f"{name} must be {wanted}, got {value!r}{hint}")


def _build(cls, data: dict | None, where: str):
    data = data or {}
    if not isinstance(data, dict):
        raise ConfigError(f"{where} must be a mapping, got {type(data).__name__}")
    refuse_unknown_keys(data, {f.name for f in fields(cls)}, f"{where}.")
    return cls(**data)


#: The shipped adapters a warm start may name (``init_adapter: finetuned``), by ``--model``
#: name.
SHIPPED_ADAPTERS = {"finetuned": FINETUNED_LORA}
#: ``precision`` values (``auto`` picks by machine: :func:`hf_model.training_dtype`).
PRECISIONS = ("auto", "bf16", "fp32")
#: Run settings that leave the adapter as it is: how often a run checkpoints, how many
#: checkpoints it keeps, and the held-out check at its end. A resumed run may change
#: them, and a recipe stage's identity leaves them out.
BOOKKEEPING = frozenset({"eval_pairs", "checkpoint_every", "keep_checkpoints"})


@dataclass(frozen=True)
class LoraSettings:
    """The adapter.

    Args:
        r: Rank, >= 1. Default 16.
        alpha: Scale numerator (the update is scaled by alpha / r). Default 32.
        dropout: Dropout on the adapter input, in [0, 1). Default 0.05.
        target_modules: ``all-linear`` or a list of module names.
    """

    r: int = 16
    alpha: int = 32
    dropout: float = 0.05
    target_modules: str | list[str] = "all-linear"

    def __post_init__(self) -> None:
        _number("lora.r", self.r, 1, whole=True)
        _number("lora.alpha", self.alpha, 1)
        _number("lora.dropout", self.dropout, 0, below=1)
        if not (self.target_modules == "all-linear" or isinstance(self.target_modules, list)
                and self.target_modules and all(isinstance(m, str) for m in self.target_modules)):
            raise ConfigError("lora.target_modules must be all-linear or a list of module "
                              f"names, got {self.target_modules!r}")


@dataclass(frozen=True)
class OptimSettings:
    """Optimizer and schedule.

    Args:
        lr: Peak learning rate (AdamW), > 0. Default 2e-4.
        batch_size: Sequences per step per device, >= 1. Default 8.
        grad_accum: Micro-batches per optimizer step, >= 1. Default 1.
        epochs: Passes over the training records, >= 1. Default 1.
        warmup_steps: Linear warm-up steps, >= 0. Default 20.
        weight_decay: AdamW weight decay, >= 0. Default 0.
    """

    lr: float = 2e-4
    batch_size: int = 8
    grad_accum: int = 1
    epochs: int = 1
    warmup_steps: int = 20
    weight_decay: float = 0.0

    def __post_init__(self) -> None:
        _number("optim.lr", self.lr, 0, strict=True)
        for name in ("batch_size", "grad_accum", "epochs"):
            _number(f"optim.{name}", getattr(self, name), 1, whole=True)
        _number("optim.warmup_steps", self.warmup_steps, 0, whole=True)
        _number("optim.weight_decay", self.weight_decay, 0)


@dataclass(frozen=True)
class DataSettings:
    """Which records to train on.

    Args:
        split: Prepared split (``paper``, ``disjoint``, ``timed``, ``compositional``).
        seed: Seed the split was prepared with.
        version: The split's prepared version (12 hex digits), pinned so that the run
            can be repeated after the data changed; ``None``: the version this release
            registers in ``data/versions.json``.
        forms: ``lifted``, ``grounded`` or both.
        limit: Use only the first N training records (``None``: all).
        shots: Worked examples per prompt. Each batch draws one count from this list
            and that many examples from the training records (none of its own rows),
            which all its prompts share, as the prompts of one evaluation run do.
            ``[0]`` trains zero-shot only; ``[0, 5, 20]`` prepares the adapter for the
            few-shot variants as well.
        repeat: Times each record of a source occurs in an epoch (source name ->
            count >= 1; sources not named occur once), e.g. ``{nl2tl_timed_train: 2}``
            to weight a part of the mixture up without a new data version. The copies
            count in ``train_examples`` and are drawn as worked examples as often.
        pairs: A file of your own pairs (JSON Lines as ``ara translate-file`` reads,
            each line with its reference ``stl``), added to the split's training
            records as the source ``pairs`` (weight them with ``repeat: {pairs: N}``);
            ``run.json`` records its hash.
    """

    split: str = "paper"
    seed: int = 0
    version: str | None = None
    forms: tuple[str, ...] = ("lifted", "grounded")
    limit: int | None = None
    shots: tuple[int, ...] = (0,)
    repeat: dict[str, int] = field(default_factory=dict)
    pairs: str | None = None

    def __post_init__(self) -> None:
        for name in ("forms", "shots"):
            value = getattr(self, name)
            if isinstance(value, (str, int)):  # shots: 5 for [5]
                raise ConfigError(f"data.{name} must be a list, e.g. [{value}], got {value!r}")
            object.__setattr__(self, name, tuple(value))
        if not self.shots or any(not isinstance(k, int) or k < 0 for k in self.shots):
            raise ConfigError(f"data.shots must be a list of counts >= 0, got {self.shots}")
        bad = [f for f in self.forms if f not in ("lifted", "grounded")]
        if bad or not self.forms:
            raise ConfigError(f"data.forms must name lifted and/or grounded, got {self.forms}")
        if self.version is not None and not re.fullmatch(r"[0-9a-f]{12}", str(self.version)):
            raise ConfigError(f"data.version must be 12 hex digits (a prepared version, "
                              f"see data/versions.json) or null, got {self.version!r}")
        _number("data.limit", self.limit, 1, whole=True, none=True)
        _number("data.seed", self.seed, 0, whole=True)
        if not isinstance(self.repeat, dict) or any(
                not isinstance(k, int) or isinstance(k, bool) or k < 1
                for k in self.repeat.values()):
            raise ConfigError(f"data.repeat must map source names to counts >= 1, "
                              f"got {self.repeat!r}")

    def resolved_version(self) -> str | None:
        """The version the run trains on: the pinned one, else the one this release
        registers (None where it registers none for this seed)."""
        from ara.data import registered_version

        return self.version or registered_version(self.split, self.seed)


@dataclass(frozen=True)
class TrainConfig:
    """One fine-tuning run.

    Args:
        base_model: ``default`` (the embedded Gemma 3 270M, converted by ``ara model
            prepare``), a local HF folder, or a hub id already in the local cache.
        out: Run folder: checkpoints, the adapter, ``train_log.jsonl``, ``run.json``.
        seed: Seeds the data order, dropout and adapter initialization.
        init_adapter: A PEFT adapter folder (``adapter/`` of an earlier run) to start
            from instead of a fresh LoRA: a warm start with its own optimizer and
            schedule, for a second pass or new data. Its LoRA shape must match ``lora``.
            ``finetuned`` names the shipped adapter (``--model finetuned``) in its PEFT
            form, to adapt it to pairs of your own.
        max_steps: Stop after this many optimizer steps (``None``: the epochs decide).
        checkpoint_every: Save a resumable checkpoint every N steps, >= 1.
        keep_checkpoints: How many of the newest checkpoints to keep, >= 1. Each holds
            the whole model state, so keeping all of them fills a disk over a few runs.
        eval_pairs: Test pairs for the held-out check at the end (0: none).
        precision: What the frozen base model computes in: ``bf16``, ``fp32``, or
            ``auto`` (default): bf16 where the hardware multiplies it natively (a CUDA
            GPU since Ampere; a CPU with AMX or AVX512-BF16, such as Intel Xeon since
            Sapphire Rapids and AMD EPYC since Zen 4), fp32 elsewhere (without them bf16
            is emulated, slowly). The LoRA weights and the
            optimizer stay fp32, and the loss is taken in fp32. It is no part of what a
            run trains (a recipe stage's identity leaves it out): a resumed run may go on
            in another, on another machine; each log line records the one of its step.
        lora, optim, data: Sub-configs (see each).
    """

    base_model: str = "default"
    out: str = "runs/train/gemma3-270m-lora"
    seed: int = 0
    init_adapter: str | None = None
    max_steps: int | None = None
    checkpoint_every: int = 100
    keep_checkpoints: int = 2
    eval_pairs: int = 100
    precision: str = "auto"
    lora: LoraSettings = field(default_factory=LoraSettings)
    optim: OptimSettings = field(default_factory=OptimSettings)
    data: DataSettings = field(default_factory=DataSettings)

    def __post_init__(self) -> None:
        _number("max_steps", self.max_steps, 1, whole=True, none=True)
        _number("checkpoint_every", self.checkpoint_every, 1, whole=True)
        _number("keep_checkpoints", self.keep_checkpoints, 1, whole=True)
        _number("eval_pairs", self.eval_pairs, 0, whole=True)
        _number("seed", self.seed, 0, whole=True)
        if self.precision not in PRECISIONS:
            raise ConfigError(f"precision must be one of {', '.join(PRECISIONS)}, "
                              f"got {self.precision!r}")
        if self.init_adapter is not None and not str(self.init_adapter).strip():
            raise ConfigError("init_adapter must be an adapter folder or null, got ''")

    def steps_for(self, examples: int) -> int:
        """Optimizer steps over ``examples`` training records: micro-batches of
        ``batch_size`` for ``epochs``, ``grad_accum`` a step, at most ``max_steps``."""
        optim = self.optim
        total = -(-examples // optim.batch_size) * optim.epochs // optim.grad_accum
        return min(total, self.max_steps or total)

    @property
    def init_adapter_folder(self) -> Path | None:
        """Where ``init_adapter`` is: a folder, or by its name a shipped adapter's PEFT form
        (converted from its GGUF into the cache on first use)."""
        if self.init_adapter is None:
            return None
        if self.init_adapter in SHIPPED_ADAPTERS:
            from ara.training.export import shipped_peft

            return shipped_peft(SHIPPED_ADAPTERS[self.init_adapter])
        return Path(self.init_adapter)

    @classmethod
    def from_dict(cls, data: dict) -> TrainConfig:
        data = dict(data)
        subs = {"lora": LoraSettings, "optim": OptimSettings, "data": DataSettings}
        parts = {k: _build(c, data.pop(k, None), k) for k, c in subs.items()}
        return cls(**_checked(cls, data), **parts)

    @classmethod
    def from_yaml(cls, path: str | Path) -> TrainConfig:
        return cls.from_dict(read_config(path))

    def to_dict(self) -> dict:
        data = asdict(self)
        data["data"]["forms"] = list(self.data.forms)
        data["data"]["shots"] = list(self.data.shots)
        return data

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, indent=2)


def _checked(cls, data: dict) -> dict:
    refuse_unknown_keys(data, {f.name for f in fields(cls)} - {"lora", "optim", "data"})
    return data
