"""A weighted average of LoRA adapters, written as one exact LoRA adapter.

Adapters trained from the same start (the recipe's refinements all grow from its first
stage) can be averaged in weight space, a "model soup" (Wortsman et al., 2022): runs
that each learned a little of something different often keep both in the average.

LoRA factors cannot be averaged directly (``mean(B) @ mean(A)`` is not
``mean(B @ A)``), but the average of the updates is itself a LoRA of the summed rank:
stack the ``A`` factors and place each weighted ``B`` beside the others,

    sum_i w_i s_i B_i A_i  =  s [w_1 s_1/s B_1 | ... | w_n s_n/s B_n] [A_1; ...; A_n],

with ``s_i = alpha_i / r_i`` each adapter's scaling and ``s`` the result's. The result is
exact, loads in PEFT and converts to a GGUF LoRA like any adapter (two rank-16 adapters
make one of rank 32).

The summed rank costs time at every token (llama.cpp applies a LoRA unmerged), so
:func:`reduce_rank` brings an adapter back to a smaller rank: each module's update
``s B A`` is replaced by its best rank-``k`` approximation (Eckart-Young: the truncated
SVD), computed from the thin factors without forming the full matrix. What is dropped
is reported as the share of each update's squared norm kept.
"""

from __future__ import annotations

import json
import math
import shutil
from dataclasses import dataclass
from pathlib import Path

from ara.errors import ConfigError

CONFIG = "adapter_config.json"
WEIGHTS = "adapter_model.safetensors"
TOKENIZER_FILES = ("tokenizer.json", "tokenizer_config.json")


@dataclass(frozen=True)
class SoupPart:
    """One adapter folder (PEFT layout) and its weight in the average."""

    adapter: Path
    weight: float = 1.0

    def __post_init__(self) -> None:
        _check_weight(self.weight)


def _load(adapter: Path) -> tuple[dict, dict]:
    from safetensors.torch import load_file

    config_file, weights_file = adapter / CONFIG, adapter / WEIGHTS
    if not config_file.is_file() or not weights_file.is_file():
        raise ConfigError(f"{adapter} is not a PEFT LoRA adapter folder "
                          f"(needs {CONFIG} and {WEIGHTS})")
    config = json.loads(config_file.read_text())
    if (config.get("peft_type") != "LORA" or config.get("rank_pattern")
            or config.get("alpha_pattern")):
        raise ConfigError(f"{adapter}: only plain LoRA adapters (one rank, one alpha) average")
    if config.get("use_dora"):
        raise ConfigError(f"{adapter}: DoRA adapters do not average as LoRA updates")
    return config, load_file(str(weights_file))


def _setting(config: dict, key: str):
    """A config value, lists compared as sets (PEFT writes target_modules in any order)."""
    value = config.get(key)
    return frozenset(value) if isinstance(value, list) else value


def _rank_divisor(config: dict, rank: int) -> float:
    """What PEFT divides alpha by for ``rank``: the rank, or its root with rsLoRA."""
    return math.sqrt(rank) if config.get("use_rslora") else rank


def _scaling(config: dict) -> float:
    """The factor PEFT puts in front of ``B A``."""
    return config["lora_alpha"] / _rank_divisor(config, config["r"])


def _write(out: Path, weights: dict, config: dict, source: Path, extras: tuple[str, ...],
           record_name: str, record: dict) -> None:
    """An adapter folder: the factors, their config, ``extras`` copied from ``source``
    (unless that is ``out`` itself) and the record of how it was made."""
    from safetensors.torch import save_file

    out.mkdir(parents=True, exist_ok=True)
    save_file(weights, str(out / WEIGHTS))
    (out / CONFIG).write_text(json.dumps(config, indent=2) + "\n")
    for extra in extras:
        if (source / extra).is_file() and source.resolve() != out.resolve():
            shutil.copy2(source / extra, out / extra)
    (out / record_name).write_text(json.dumps(record, indent=2) + "\n")


def average_adapters(parts: list[SoupPart], out: Path) -> dict:
    """Write the weighted mean of ``parts`` (weights normalized to sum 1) to ``out``.

    Returns the soup's record (its parts, rank and alpha), also written to ``soup.json``.
    """
    import torch

    if len(parts) < 2:
        raise ConfigError("a soup needs at least two adapters")
    loaded = [_load(p.adapter) for p in parts]
    first_config, first_weights = loaded[0]
    for part, (config, weights) in zip(parts[1:], loaded[1:], strict=True):
        if set(weights) != set(first_weights) or any(
                _setting(config, k) != _setting(first_config, k)
                for k in ("base_model_name_or_path", "target_modules", "use_rslora", "use_dora")):
            raise ConfigError(f"{part.adapter} does not adapt the same modules of the same "
                              f"base as {parts[0].adapter}: they cannot be averaged")
    total = sum(p.weight for p in parts)
    scalings = [_scaling(c) for c, _ in loaded]
    rank = sum(c["r"] for c, _ in loaded)
    # Keep the first adapter's scaling; each B factor carries its own ratio to it.
    scaling = scalings[0]
    alpha = scaling * _rank_divisor(first_config, rank)
    merged: dict[str, torch.Tensor] = {}
    for key, tensor in first_weights.items():
        if ".lora_A." in key:
            merged[key] = torch.cat([w[key] for _, w in loaded], dim=0).contiguous()
        elif ".lora_B." in key:
            merged[key] = torch.cat([
                w[key] * (part.weight / total) * (s / scaling)
                for part, (_, w), s in zip(parts, loaded, scalings, strict=True)
            ], dim=1).to(tensor.dtype).contiguous()
        else:
            raise ConfigError(f"{parts[0].adapter}: tensor {key} is not a LoRA factor")
    record = {"parts": [{"adapter": str(p.adapter), "weight": p.weight / total} for p in parts],
              "rank": rank, "lora_alpha": alpha}
    _write(out, merged, dict(first_config, r=rank, lora_alpha=alpha), parts[0].adapter,
           TOKENIZER_FILES, "soup.json", record)
    return record


def _truncated_factors(b, a, rank: int):
    """``(B', A', kept)``: the best rank-``rank`` factors of ``B @ A`` and the share of its
    squared Frobenius norm they keep. Works on the thin QR factors, so the cost follows
    the adapter's rank, not the module's size."""
    import torch

    q_b, r_b = torch.linalg.qr(b)          # B = Q_b R_b
    q_a, r_a = torch.linalg.qr(a.T)        # A = R_a^T Q_a^T
    u, sigma, vh = torch.linalg.svd(r_b @ r_a.T, full_matrices=False)
    root = sigma[:rank].sqrt()
    total = float((sigma ** 2).sum())
    kept = float((sigma[:rank] ** 2).sum()) / total if total > 0 else 1.0
    b_new, a_new = (q_b @ u[:, :rank]) * root, root[:, None] * (vh[:rank] @ q_a.T)
    # A module narrower than the rank has fewer singular values: the rest are zero.
    missing = rank - b_new.shape[1]
    if missing > 0:
        b_new = torch.cat([b_new, b_new.new_zeros(b_new.shape[0], missing)], dim=1)
        a_new = torch.cat([a_new, a_new.new_zeros(missing, a_new.shape[1])], dim=0)
    return b_new, a_new, kept


def reduce_rank(adapter: Path, rank: int, out: Path) -> dict:
    """Write to ``out`` the rank-``rank`` adapter nearest ``adapter`` (each module's update
    truncated by SVD, the scaling ``alpha / r`` kept).

    Returns its record (rank, the rank it came from, the share of the updates' squared
    norm kept: the least over modules and the mean), also written to ``reduced.json``.
    """
    import torch

    config, weights = _load(adapter)
    if not isinstance(rank, int) or not 1 <= rank <= config["r"]:
        raise ConfigError(f"a reduced rank must be between 1 and the adapter's rank "
                          f"{config['r']}, got {rank}")
    reduced: dict[str, torch.Tensor] = {}
    kept: list[float] = []
    for key, tensor in weights.items():
        if ".lora_A." in key:
            continue
        if ".lora_B." not in key:
            raise ConfigError(f"{adapter}: tensor {key} is not a LoRA factor")
        key_a = key.replace(".lora_B.", ".lora_A.")
        b, a, share = _truncated_factors(tensor.float(), weights[key_a].float(), rank)
        reduced[key] = b.to(tensor.dtype).contiguous()
        reduced[key_a] = a.to(weights[key_a].dtype).contiguous()
        kept.append(share)
    alpha = _scaling(config) * _rank_divisor(config, rank)
    record = {"rank": rank, "from_rank": config["r"], "lora_alpha": alpha,
              "norm_kept": {"least": round(min(kept), 6),
                            "mean": round(sum(kept) / len(kept), 6)}}
    # A reduced soup keeps the record of its parts.
    _write(out, reduced, dict(config, r=rank, lora_alpha=alpha), adapter,
           TOKENIZER_FILES + ("soup.json",), "reduced.json", record)
    return record


def _check_weight(weight) -> None:
    if (not isinstance(weight, (int, float)) or isinstance(weight, bool)
            or not math.isfinite(weight) or weight <= 0):
        raise ConfigError(f"a soup weight must be a positive number, got {weight!r}")


def check_soup(parts: int, weights: list | None, rank: int | None, noun: str = "run") -> None:
    """A soup's settings, before anything is read: ``weights`` one positive number per
    part, at least two parts or one and a ``rank`` (a positive whole number)."""
    if weights is not None:
        if not isinstance(weights, (list, tuple)) or len(weights) != parts:
            count = len(weights) if isinstance(weights, (list, tuple)) else weights
            raise ConfigError(f"{count} weights for {parts} {noun}s: one per {noun}, in order")
        for w in weights:
            _check_weight(w)
    if parts < 2 and rank is None:
        raise ConfigError(f"a soup needs at least two {noun}s (or one and a rank to reduce "
                          "it to)")
    if rank is not None and (not isinstance(rank, int) or isinstance(rank, bool) or rank < 1):
        raise ConfigError(f"a reduced rank is a positive whole number, got {rank!r}")


def soup_runs(runs: list[Path], weights: list[float] | None, out: Path,
              rank: int | None = None) -> dict:
    """Average finished ``ara train`` runs into the run folder ``out`` (``adapter/``,
    ``run.json``), optionally reduced to ``rank``; one run is enough with ``rank``.

    Returns the run record written to ``out/run.json``: the first run's (base model and
    data version, which export needs) with the soup's own parts under ``soup`` and
    ``reduced``.
    """
    check_soup(len(runs), weights, rank)
    weights = list(weights or [1.0] * len(runs))
    for run in runs:
        if not (Path(run) / "run.json").is_file():
            raise ConfigError(f"{run} is not an `ara train` run folder (no run.json)")
    record = json.loads((Path(runs[0]) / "run.json").read_text())
    adapter = Path(out) / "adapter"
    if len(runs) > 1:
        parts = [SoupPart(Path(run) / "adapter", w) for run, w in zip(runs, weights, strict=True)]
        record["soup"] = average_adapters(parts, adapter)
    if rank is not None:
        source = adapter if len(runs) > 1 else Path(runs[0]) / "adapter"
        record["reduced"] = reduce_rank(source, rank, adapter)
    Path(out).mkdir(parents=True, exist_ok=True)
    (Path(out) / "run.json").write_text(json.dumps(record, indent=2) + "\n")
    return record
