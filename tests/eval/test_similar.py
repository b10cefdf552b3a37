"""Worked examples chosen by similarity: the pairs whose wording around the propositions
is most like the request's."""

import pytest

from ara.data import Record
from ara.eval.harness import AblationConfig, plan
from ara.eval.translate.similar import SimilarExamples, index_for, logic_words, pool_hash


def record(nl, stl, aps, i=0):
    return Record(uid=f"u{i}", nl=nl, stl=stl, aps=tuple(sorted(aps)), source="test",
                  form="grounded", row=i)


POOL = [
    record("Go to the kitchen, then to the garage.", "F(go_to_kitchen & F(go_to_garage))",
           ["go_to_kitchen", "go_to_garage"], 0),
    record("Never touch the stove.", "G(!touch_stove)", ["touch_stove"], 1),
    record("Whenever the door opens, ring the bell within 5 steps.",
           "G(door_open -> F[0,5](ring_bell))", ["door_open", "ring_bell"], 2),
    record("Visit the lab and the office in any order.", "F(visit_lab) & F(visit_office)",
           ["visit_lab", "visit_office"], 3),
]


def test_the_words_of_the_propositions_and_the_numbers_are_masked():
    assert logic_words("Whenever ( prop_1 ) holds, ( prop_2 ) within 12 steps",
                       ["prop_1", "prop_2"]) == [
        "whenever", "<p>", "holds", "<p>", "within", "<n>", "steps"]
    # Lifted and grounded requests of one shape read alike.
    assert logic_words("Never touch the stove", ["touch_stove"]) == ["never", "<p>", "the", "<p>"]


def test_the_pair_of_the_same_shape_is_nearest_whatever_it_names():
    index = SimilarExamples(POOL)
    near = index.nearest("Whenever the alarm sounds, leave the building within 30 steps.",
                         ["alarm_sounds", "leave_building"], 2)
    assert near[-1].uid == "u2"  # the most similar stands last, next to the request
    assert [r.uid for r in index.nearest("Head to the dock, then to the gate.",
                                         ["head_to_dock", "head_to_gate"], 1)] == ["u0"]
    assert [r.uid for r in index.nearest("Never open the freezer.", ["open_freezer"], 1)] == [
        "u1"]


def test_measuring_never_shows_the_request_its_own_sentence():
    index = SimilarExamples(POOL)
    own = "never touch the stove"
    assert index.nearest(own, ["touch_stove"], 1)[0].uid == "u1"
    assert index.nearest(own, ["touch_stove"], 1, other_sentences=True)[0].uid != "u1"
    with pytest.raises(ValueError, match="pool of 4"):
        index.nearest(own, ["touch_stove"], 5)


def test_an_index_is_built_once_per_content_and_kept_on_disk(tmp_path, monkeypatch):
    monkeypatch.setenv("ARA_CACHE", str(tmp_path))
    index = index_for(POOL)
    assert index_for(list(POOL)) is index
    assert (tmp_path / "similar" / f"{pool_hash(POOL)}.pkl").is_file()
    assert pool_hash(POOL) != pool_hash(POOL[:3]) != pool_hash(POOL[::-1])


def test_an_index_kept_by_another_version_is_built_again(tmp_path, monkeypatch):
    """Tests that a cache whose classes lived in a module since moved (as ara.eval.similar
    did) is rebuilt, not an error."""
    monkeypatch.setenv("ARA_CACHE", str(tmp_path))
    stale = tmp_path / "similar" / f"{pool_hash(POOL[:2])}.pkl"
    stale.parent.mkdir()
    stale.write_bytes(b"cara.eval.similar\nSimilarExamples\n(tR.")  # protocol 0
    assert len(index_for(POOL[:2]).pool) == 2


def test_the_harness_gives_each_test_pair_its_own_similar_examples(paper_split):
    config = AblationConfig(split="paper", variants=("F+C", "C"), shots=(2,), reruns=1,
                            limit=6, examples_by="similar")
    jobs = list(plan(config, paper_split))
    few = [j for j in jobs if j.variant.few_shot]
    assert len(few) == 6 and all(len(j.examples) == 2 for j in few)
    assert all(j.record.nl not in {e.nl for e in j.examples} for j in few)
    assert len({j.examples for j in few}) > 1  # chosen per pair, not once per run
    assert all(j.examples == () for j in jobs if not j.variant.few_shot)
    assert "examples_by" in config.to_dict()
    assert "examples_by" not in AblationConfig(split="paper").to_dict()  # old runs resume
    with pytest.raises(Exception, match="examples by 'nearest'"):
        AblationConfig(split="paper", examples_by="nearest")


def test_your_own_pairs_give_the_examples_most_like_the_request(tmp_path):
    """Tests `ara translate --shots 1 --examples-by similar --examples FILE`'s choice: the
    pair of the user's file whose wording is most like the request, of the request's
    form; random draws from the same file; a bad option is named."""
    import json

    from ara.errors import ConfigError
    from ara.eval.translate.answering import worked_examples

    pairs = tmp_path / "lab.jsonl"
    pairs.write_text("".join(json.dumps({"nl": r.nl, "aps": list(r.aps), "stl": r.stl}) + "\n"
                             for r in POOL))
    shown = worked_examples("finetuned", 1, ["hold_dock", "hold_gate"], nl="Hold the dock, "
                            "then the gate.", by="similar", pool=pairs)
    assert [s.stl for s in shown] == ["F(go_to_kitchen & F(go_to_garage))"]
    drawn = worked_examples("finetuned", 2, ["a_b"], seed=1, pool=pairs)
    assert len(drawn) == 2 and {s.nl for s in drawn} <= {r.nl for r in POOL}
    assert worked_examples("finetuned", None, ["a_b"], nl="x", by="similar", pool=pairs) == []
    with pytest.raises(ConfigError, match="only 4 grounded pairs"):
        worked_examples("finetuned", 5, ["a_b"], pool=pairs)
    with pytest.raises(ConfigError, match="examples by 'closest'"):
        worked_examples("finetuned", 1, ["a_b"], by="closest", pool=pairs)
