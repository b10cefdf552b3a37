"""Training examples in the evaluation prompt's layout, with loss on the answer only.

The prompt is :func:`ara.eval.prompt.build_prompt` with no worked examples, and the
answer is what a model writes after ``"STL:"`` at evaluation time: a space, the
canonical formula, the newline that ends it. The two are tokenized separately, as
the prompt is at inference, so the model learns the token boundary it will meet.
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import torch

from ara.data.normalize import Record
from ara.eval.prompt import STOP, build_prompt
from ara.eval.translator import ANSWER_PREFIX

IGNORE = -100


@dataclass(frozen=True)
class Example:
    """One tokenized pair: prompt ids, then answer ids (the only ones with a loss)."""

    prompt_ids: tuple[int, ...]
    answer_ids: tuple[int, ...]

    @property
    def length(self) -> int:
        return len(self.prompt_ids) + len(self.answer_ids)


def encode(records: Sequence[Record], tokenizer) -> list[Example]:
    """Tokenize records into examples."""
    examples = []
    for r in records:
        prompt = tokenizer(build_prompt(r.nl, r.aps, ()), add_special_tokens=True)["input_ids"]
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


def batches(examples: Sequence[Example], batch_size: int, seed: int, epoch: int,
            skip: int = 0) -> Iterator[list[Example]]:
    """The batches of one epoch in a seeded order, after skipping ``skip`` of them.

    The order depends only on (seed, epoch), so a resumed run sees the same batches.
    """
    order = list(range(len(examples)))
    random.Random(f"{seed}:{epoch}").shuffle(order)
    for start in range(skip * batch_size, len(order), batch_size):
        yield [examples[i] for i in order[start: start + batch_size]]


def answer_loss(model, batch: dict[str, torch.Tensor]) -> torch.Tensor:
    """Mean cross-entropy over answer tokens, computing the vocabulary head only there.

    Gemma's output layer (262k x hidden) costs more than the rest of a 270M model; the
    logits at position t predict token t+1, so only the positions right before an
    answer token are kept (``logits_to_keep`` with those indices).
    """
    labels = batch["labels"]
    targets = labels[:, 1:]
    keep = (targets != IGNORE).any(dim=0).nonzero().squeeze(1)
    out = model(input_ids=batch["input_ids"], attention_mask=batch["attention_mask"],
                logits_to_keep=keep)
    logits = out.logits  # (batch, len(keep), vocab)
    gathered = targets[:, keep]
    return torch.nn.functional.cross_entropy(
        logits.float().reshape(-1, logits.shape[-1]), gathered.reshape(-1), ignore_index=IGNORE)
