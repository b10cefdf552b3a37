"""Training examples in the evaluation prompt's layout, with loss on the answer only.

The prompt is :func:`ara.eval.translate.prompt.build_prompt`, with the worked examples a batch
drew (none for zero-shot training), and the answer is what a model writes after
``"STL:"`` at evaluation time: a space, the canonical formula, the newline that ends
it. The two are tokenized separately, as the prompt is at inference, so the model
learns the token boundary it will meet.
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import torch

from ara.data.normalize import Record
from ara.errors import ConfigError
from ara.eval.translate.prompt import ANSWER_PREFIX, STOP, Shot, build_prompt
from ara.kv_cache import cache_of, with_cache
from ara.output_layer import output_rows

IGNORE = -100


@dataclass(frozen=True)
class Example:
    """One tokenized pair: prompt ids, then answer ids (the only ones with a loss)."""

    prompt_ids: tuple[int, ...]
    answer_ids: tuple[int, ...]

    @property
    def length(self) -> int:
        return len(self.prompt_ids) + len(self.answer_ids)


def encode(records: Sequence[Record], tokenizer, shots: Sequence[Shot] = ()) -> list[Example]:
    """Tokenize records into examples whose prompts show ``shots`` first."""
    examples = []
    for r in records:
        prompt = tokenizer(build_prompt(r.nl, r.aps, shots),
                           add_special_tokens=True)["input_ids"]
        answer = tokenizer(f"{ANSWER_PREFIX}{r.stl}{STOP}", add_special_tokens=False)["input_ids"]
        examples.append(Example(tuple(prompt), tuple(answer)))
    return examples


def collate(batch: Sequence[Example], pad_id: int) -> dict[str, torch.Tensor]:
    """Right-padded ``input_ids``, ``attention_mask`` and ``labels`` (IGNORE off-answer)."""
    width = max(e.length for e in batch)
    ids = torch.full((len(batch), width), pad_id, dtype=torch.long)
    labels = torch.full((len(batch), width), IGNORE, dtype=torch.long)
    mask = torch.zeros((len(batch), width), dtype=torch.long)
    for i, e in enumerate(batch):
        seq = e.prompt_ids + e.answer_ids
        ids[i, : len(seq)] = torch.tensor(seq)
        mask[i, : len(seq)] = 1
        labels[i, len(e.prompt_ids): len(seq)] = torch.tensor(e.answer_ids)
    return {"input_ids": ids, "attention_mask": mask, "labels": labels}


def repeat_sources(records: Sequence[Record], repeat: dict[str, int]) -> list[Record]:
    """``records`` with each record of a source in ``repeat`` occurring that many times
    (in place, so the seeded shuffle of :func:`batches` spreads the copies).

    Raises:
        ConfigError: If ``repeat`` names a source that no record has, which is a typo
            or a mixture without that source, and would otherwise weight nothing.
    """
    sources = {r.source for r in records}
    unknown = sorted(set(repeat) - sources)
    if unknown:
        raise ConfigError(f"data.repeat names sources the training records lack: {unknown}; "
                          f"they have {sorted(sources)}")
    return [r for r in records for _ in range(repeat.get(r.source, 1))]


def batches(items: Sequence, batch_size: int, seed: int, epoch: int,
            skip: int = 0) -> Iterator[list]:
    """The batches of one epoch in a seeded order, after skipping ``skip`` of them.

    The order depends only on (seed, epoch), so a resumed run sees the same batches.
    """
    order = list(range(len(items)))
    random.Random(f"{seed}:{epoch}").shuffle(order)
    for start in range(skip * batch_size, len(order), batch_size):
        yield [items[i] for i in order[start: start + batch_size]]


def shot_rng(seed: int, epoch: int, index: int) -> random.Random:
    """The generator batch ``index`` of ``epoch`` draws its worked examples from; it
    depends on nothing else, so a resumed run (or a later reader of the log) draws the
    same ones."""
    return random.Random(f"{seed}:{epoch}:{index}:shots")


def batch_shots(pool: Sequence[Record], batch: Sequence[Record], counts: Sequence[int],
                rng: random.Random) -> list[Shot]:
    """Worked examples for one batch: a count drawn from ``counts``, then that many
    distinct records of ``pool`` that share no source row with the batch (a row's
    lifted and grounded forms are one pair: showing either would give the answer away).
    """
    k = rng.choice(list(counts))
    if k == 0:
        return []
    taken = {(r.source, r.row) for r in batch}
    eligible = len({(r.source, r.row) for r in pool} - taken)
    if k > eligible:
        raise ConfigError(f"asked for {k} shots; only {eligible} training pairs are eligible "
                          "beside the batch: lower data.shots or train on more records")
    shots: list[Shot] = []
    while len(shots) < k:
        r = pool[rng.randrange(len(pool))]
        if (r.source, r.row) not in taken:
            taken.add((r.source, r.row))
            shots.append(Shot.of(r))
    return shots


def shared_prefix_length(batch: dict[str, torch.Tensor]) -> int:
    """How many leading tokens every row of ``batch`` has in common (all unpadded)."""
    ids, mask = batch["input_ids"], batch["attention_mask"]
    same = (ids == ids[:1]).all(dim=0) & mask.bool().all(dim=0)
    differs = (~same).nonzero()
    return int(differs[0]) if len(differs) else ids.shape[1]


def answer_loss(model, batch: dict[str, torch.Tensor], share_prefix: bool = True) -> torch.Tensor:
    """Mean cross-entropy over answer tokens (see :func:`answer_loss_sum`)."""
    total, count = answer_loss_sum(model, batch, share_prefix)
    return total / count


def answer_loss_sum(model, batch: dict[str, torch.Tensor], share_prefix: bool = True
                    ) -> tuple[torch.Tensor, int]:
    """Summed cross-entropy over answer tokens, and their number, computing the
    vocabulary head only there. Several processes sharing one batch add their sums and
    counts, so that their loss is the single-process mean over the whole batch.

    The output layer (:mod:`ara.output_layer`) runs only where it is needed: the logits
    at position t predict token t+1, so only the positions right before an answer
    token. ``logits_to_keep`` keeps columns for every row alike, and right-padded answers
    sit in different columns (their union is several times the answer tokens), so each
    row's own answer positions are picked from the kept columns before the output layer
    runs.

    Every prompt starts with the same instructions, about half of a training sequence.
    With ``share_prefix`` that common prefix runs once, for one row, and its keys and
    values are repeated across the batch: the same loss and the same gradients (the
    repeat sums them back), at about half the compute.
    """
    targets = batch["labels"][:, 1:]
    answered = targets != IGNORE
    keep = answered.any(dim=0).nonzero().squeeze(1)
    rows, cols = answered.nonzero(as_tuple=True)
    gathered = targets[rows, cols]
    # Where each answer position sits among the kept columns.
    picked = torch.searchsorted(keep, cols)
    ids, mask = batch["input_ids"], batch["attention_mask"]
    shared = min(shared_prefix_length(batch), int(keep.min())) if share_prefix else 0
    if shared < 2 or ids.shape[0] == 1:
        inputs = {"input_ids": ids, "attention_mask": mask, "logits_to_keep": keep}
    else:
        # The prefix's keys and values are wanted, no logit.
        with output_rows(model, lambda h: h[0, :0]):
            prefix = model(input_ids=ids[:1, :shared], use_cache=True, logits_to_keep=1)
        cache = cache_of(prefix)
        cache.batch_repeat_interleave(ids.shape[0])
        inputs = {"input_ids": ids[:, shared:], "attention_mask": mask,
                  **with_cache(cache), "logits_to_keep": keep - shared}
    with output_rows(model, lambda h: h[rows, picked]):
        out = model(**inputs)
    logits = out.logits.reshape(-1, out.logits.shape[-1])  # (answer tokens, vocab)
    total = torch.nn.functional.cross_entropy(logits.float(), gathered, reduction="sum")
    return total, int(gathered.numel())


def own_pairs(path: str) -> list:
    """A user's pairs file as training records of the source ``pairs``."""
    from ara.eval.translate.request_file import read_pairs
    from ara.eval.translate.translator import TranslatorConfig

    return [replace(r, source="pairs") for r in read_pairs(Path(path), TranslatorConfig())]
