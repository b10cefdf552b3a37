"""Training examples: the evaluation prompt, with the worked examples a batch drew."""

import random

import pytest

from ara.data.normalize import Record
from ara.errors import ConfigError
from ara.eval.translate.prompt import build_prompt
from ara.training.dataset import batch_shots, batches, encode, repeat_sources


def record(row: int, form: str = "lifted") -> Record:
    return Record(uid=f"{row}{form}", nl=f"go to (prop_1) {row}", stl=f"F(prop_{row % 3 + 1})",
                  aps=(f"prop_{row % 3 + 1}",), source="navi", form=form, row=row)


POOL = [record(i, form) for i in range(30) for form in ("lifted", "grounded")]


def test_a_batch_never_sees_its_own_rows_among_its_shots():
    """Tests that neither form of a batch's rows is shown to it, and that the shots
    are distinct pairs."""
    rng = random.Random(0)
    for batch in batches(POOL, 8, seed=0, epoch=0):
        shots = batch_shots(POOL, batch, [20], rng)
        rows = {r.nl.split()[-1] for r in batch}
        shown = [s.nl.split()[-1] for s in shots]
        assert len(shots) == 20 and len(set(shown)) == 20
        assert not rows & set(shown)


def test_the_count_is_drawn_from_the_list_and_seeded():
    """Tests that every listed count occurs, and that the same seed draws the same."""
    draw = [len(batch_shots(POOL, POOL[:2], [0, 2, 5], random.Random(i))) for i in range(40)]
    assert set(draw) == {0, 2, 5}
    again = [len(batch_shots(POOL, POOL[:2], [0, 2, 5], random.Random(i))) for i in range(40)]
    assert draw == again


def test_too_many_shots_for_the_pool_is_a_clear_error():
    with pytest.raises(ConfigError, match="only 28 training pairs are eligible"):
        batch_shots(POOL, POOL[:4], [29], random.Random(0))


def test_prompts_are_the_evaluation_prompt_with_the_same_shots(hf_model_dir):
    """Tests that a training prompt is token for token the prompt evaluation builds."""
    from transformers import AutoTokenizer

    tokenizer = AutoTokenizer.from_pretrained(hf_model_dir)
    shots = batch_shots(POOL, POOL[:1], [5], random.Random(1))
    (example,) = encode(POOL[:1], tokenizer, shots)
    prompt = build_prompt(POOL[0].nl, POOL[0].aps, shots)
    assert list(example.prompt_ids) == tokenizer(prompt)["input_ids"]
    assert tokenizer.decode(example.answer_ids) == f" {POOL[0].stl}\n"


def test_repeat_weights_a_source_up_and_leaves_the_others_alone():
    """Tests ``data.repeat``: twice the timed rows, the rest once, and a source no
    record has is refused instead of weighting nothing."""
    timed = [Record(uid=f"t{i}", nl=f"within {i} steps (prop_1)", stl=f"F[0,{i}](prop_1)",
                    aps=("prop_1",), source="nl2tl_timed_train", form="lifted", row=i)
             for i in range(1, 4)]
    mixed = POOL[:6] + timed
    weighted = repeat_sources(mixed, {"nl2tl_timed_train": 2})
    assert len(weighted) == 6 + 2 * 3
    assert [r.uid for r in weighted].count("t1") == 2
    assert [r for r in weighted if r.source == "navi"] == POOL[:6]
    assert repeat_sources(mixed, {}) == mixed
    with pytest.raises(ConfigError, match="lack: \\['nl2tl_timed'\\]"):
        repeat_sources(mixed, {"nl2tl_timed": 2})
