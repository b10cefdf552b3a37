"""Variants, run configs and the run plan."""

import pytest

from ara.errors import ConfigError
from ara.eval.harness import AblationConfig, Variant, plan
from ara.eval.translate.repair import RepairConfig


@pytest.mark.parametrize(
    ("name", "flags"),
    [
        ("F", (True, False, False)),
        ("f+p", (True, True, False)),  # case does not matter
        ("C+P+F", (True, True, True)),  # order does not matter; printed as F+P+C
        ("C", (False, False, True)),  # constrained zero-shot
        ("none", (False, False, False)),  # a fine-tuned model's own prompt
    ],
)
def test_variant_names_set_their_letters(name, flags):
    """Tests parsing variant names into their three switches."""
    v = Variant.parse(name)
    assert (v.few_shot, v.grammar_in_prompt, v.constrained) == flags
    assert v.name == ("+".join(x for x in "FPC" if x in name.upper()) or "none")


@pytest.mark.parametrize("name", ["F+X", "F+F", "", "FP"])
def test_bad_variant_names_say_what_is_allowed(name):
    """Tests the message for unknown letters, repeats and missing separators."""
    with pytest.raises(ConfigError, match=r"letters F \(few-shot\), P"):
        Variant.parse(name)


def test_config_round_trips_and_refuses_unknown_keys():
    """Tests AblationConfig through to_dict/from_dict, and a misspelt key."""
    config = AblationConfig(variants=("F", "f+p+c"), shots=(5,), reruns=2, limit=10)
    assert AblationConfig.from_dict(config.to_dict()) == config
    with pytest.raises(ConfigError, match="unknown key rerun. Did you mean 'reruns'"):
        AblationConfig.from_dict({**config.to_dict(), "rerun": 1})
    with pytest.raises(ConfigError, match="Did you mean 'disjoint'"):
        AblationConfig(split="disjont")


def test_repair_is_recorded_only_when_on_so_older_runs_still_resume():
    """Tests that a run without repair writes the config runs wrote before repair
    existed (a resumed run must match it), that repair is saved flat as before, and
    that it round-trips and is bounded."""
    assert not {"repair", "repair_by", "repair_doubt"} & set(AblationConfig().to_dict())
    repaired = AblationConfig(repair=RepairConfig(8))
    saved = repaired.to_dict()
    assert (saved["repair"], saved["repair_by"], saved["repair_doubt"]) == (8, "samples+edits",
                                                                            0.5)
    assert AblationConfig.from_dict(saved) == repaired
    with pytest.raises(ConfigError, match="repair draws 0 to 32 answers"):
        AblationConfig(repair=RepairConfig(33))
    with pytest.raises(ConfigError, match=r"choose one of samples\+edits, edits, samples"):
        AblationConfig(repair=RepairConfig(8, by="votes"))
    with pytest.raises(ConfigError, match=r"doubt is a probability, 0 to 1 \(0: gaps only\); "
                                          "got 1.5"):
        AblationConfig(repair=RepairConfig(8, doubt=1.5))


def test_a_run_repaired_before_edits_existed_reads_as_repaired_by_samples():
    """Tests that a run folder written when repair only sampled keeps saying so, so that
    resuming it with repair by edits is refused instead of mixing the two."""
    old = AblationConfig(repair=RepairConfig(8)).to_dict()
    del old["repair_by"], old["repair_doubt"]
    assert AblationConfig.from_dict(old).repair.by == "samples"


def test_a_run_repaired_before_doubt_existed_reads_as_repairing_gaps_only():
    """Tests that a run folder written when repair acted on gaps alone keeps saying so
    (doubt 0), so that resuming it under the default, which also acts on answers the
    model doubts, is refused instead of mixing the two."""
    old = AblationConfig(repair=RepairConfig(8)).to_dict()
    del old["repair_doubt"]
    assert AblationConfig.from_dict(old).repair.doubt == 0.0
    assert AblationConfig(repair=RepairConfig(8)).repair.doubt == 0.5


def test_plan_covers_every_variant_shot_and_rerun_once(paper_split):
    """Tests the plan's size, uniqueness, and shared examples within a run."""
    split = paper_split
    config = AblationConfig(variants=("F", "F+P+C", "C"), shots=(2, 3), reruns=2, limit=4)
    jobs = list(plan(config, split))
    assert len(jobs) == 2 * (2 * 2 + 1) * 4  # reruns x (F variants x shots + zero-shot C) x pairs
    assert len({j.key for j in jobs}) == len(jobs)
    run = [j for j in jobs if j.rerun == 0 and j.shots == 3]
    assert len({j.examples for j in run}) == 1 and len(run[0].examples) == 3
    assert {j.examples for j in jobs if j.variant.name == "C"} == {()}
    rerun_examples = {j.rerun: j.examples for j in jobs if j.shots == 2}
    assert rerun_examples[0] != rerun_examples[1]  # examples are redrawn per rerun


def test_zero_shots_runs_f_zero_shot_and_too_many_is_refused(paper_split):
    """A user asking for zero worked examples gets them; 99,999 gets the range."""
    config = AblationConfig(variants=("F+C", "C"), shots=(0, 2), reruns=1, limit=3)
    jobs = list(plan(config, paper_split))
    assert {(j.variant.name, j.shots) for j in jobs} == {("F+C", 0), ("F+C", 2), ("C", 0)}
    assert all(j.examples == () for j in jobs if j.shots == 0)
    with pytest.raises(ConfigError, match="shots: counts from 0 to 50"):
        AblationConfig(shots=(99999,))


def test_grammars_admit_intervals_and_the_timed_split_insists():
    """Tests that intervals are on by default, and that the timed split keeps them on
    even when a config turns them off (its references need them)."""
    from ara.eval.translate.translator import TranslatorConfig

    assert AblationConfig(split="paper").translator.intervals is True
    off = TranslatorConfig(intervals=False)
    assert AblationConfig(split="paper", translator=off).translator.intervals is False
    assert AblationConfig(split="timed", translator=off).translator.intervals is True


def test_a_test_only_split_borrows_worked_examples_from_the_compositional_train_side():
    """Tests that the hand-written suite (no train side) gets its F examples from the
    compositional mixture, and that zero-shot runs of it need no pool at all."""
    from ara.data import load_or_prepare

    split = load_or_prepare("handwritten")
    config = AblationConfig(split="handwritten", form="grounded", variants=("C", "F+C"),
                            shots=(3,), reruns=1, limit=5)
    jobs = list(plan(config, split))
    train = {r.nl for r in load_or_prepare("compositional").records("train", "grounded")}
    examples = {s.nl for j in jobs for s in j.examples}
    assert len(examples) == 3 and examples <= train
    suite = {r.nl for r in split.records("test")}
    assert not examples & suite
    zero = AblationConfig(split="handwritten", variants=("C",), reruns=1, limit=5)
    assert all(j.examples == () for j in plan(zero, split))
