"""Raw NL2TL rows to records: operators, grounding, uids, rejected rows."""

import re

from ara.data.normalize import (
    detokenize,
    grounded_name,
    lifted_from_grounded,
    lifted_tokens_to_text,
    normalize_navi,
    normalize_timed,
    read_raw,
)
from ara.data.store import RAW_DIR
from ara.grammars import parse


def navi_row(ltl, props=None, sentence="when possible pick apple and always go to house"):
    """A navi row in the raw layout, with two propositions by default."""
    props = props or {"prop_1": {"span": [2, 4], "prop": [["pick_v", "apple_n"]]},
                      "prop_2": {"span": [6, 9], "prop": [["go_to_v", "house_n"]]}}
    return {"id": 1, "sentence": sentence.split(), "ltl": [],
            "logic_sentence": "when possible ( prop_1 ) and always ( prop_2 )".split(),
            "logic_ltl": ltl.split(), "propositions": props}


def test_word_operators_and_dash_negation_become_symbols():
    """Tests the token mapping of both raw spellings."""
    assert lifted_tokens_to_text("globally ( negation prop_1 or prop_2 )".split()) == \
        "G ( ! prop_1 | prop_2 )"
    assert lifted_tokens_to_text("F ( - prop_1 ) -> prop_2".split()) == "F ( ! prop_1 ) -> prop_2"
    assert lifted_tokens_to_text(["until", "[12,65]"]) == "U [12,65]"


def test_navi_row_gives_a_lifted_and_a_grounded_record():
    """Tests one row: canonical STL, grounded names from the propositions, sorted aps."""
    records, rejected = normalize_navi([navi_row("F ( prop_1 ) & G ( prop_2 )")])
    assert rejected == []
    lifted, grounded = records
    assert (lifted.form, lifted.stl, lifted.aps) == ("lifted", "F(prop_1) & G(prop_2)",
                                                     ("prop_1", "prop_2"))
    assert lifted.nl == "when possible (prop_1) and always (prop_2)"
    assert grounded.stl == "F(pick_apple) & G(go_to_house)"
    assert grounded.aps == ("go_to_house", "pick_apple")
    assert lifted.row == grounded.row == 0


def test_malformed_rows_are_reported_not_dropped():
    """Tests that rows which do not parse, or lack a grounding, come back as rejected."""
    rows = [navi_row("F ( prop_1 prop_2 ) | F ( prop_3 )"),  # as in 26 navi rows
            navi_row("F ( prop_1 ) & F ( prop_3 )"),  # prop_3 has no grounding
            navi_row("prop_1 & prop_2")]
    records, rejected = normalize_navi(rows)
    assert [r.row for r in rejected] == [0, 1]
    assert "expected ')' or an operator, found 'prop_2'" in rejected[0].error
    assert "['prop_3'] have no grounding" in rejected[1].error
    assert {r.row for r in records} == {2}


def test_uids_are_content_hashes_unique_across_repeats():
    """Tests that identical rows get distinct, deterministic uids."""
    rows = [navi_row("prop_1 & prop_2")] * 3
    first, _ = normalize_navi(rows)
    again, _ = normalize_navi(rows)
    uids = [r.uid for r in first]
    assert len(set(uids)) == 6 and uids == [r.uid for r in again]
    assert all(re.fullmatch(r"[0-9a-f]{16}", u) for u in uids)


def test_timed_rows_keep_their_intervals():
    """Tests a timed row with word operators and an interval token."""
    row = {"logic_ltl": "globally ( prop_1 imply finally [12,65] ( prop_2 ) )".split(),
           "logic_sentence": "( prop_1 ) means ( prop_2 ) soon".split()}
    (record,), rejected = normalize_timed([row])
    assert record.stl == "G(prop_1 -> F[12,65](prop_2))" and rejected == []


def test_tokens_join_into_a_sentence_and_wordnet_senses_into_a_name():
    """Tests detokenize and grounded_name."""
    assert detokenize("if ( prop_1 ) , then go".split()) == "if (prop_1), then go"
    assert grounded_name(["go_to_v", "waste_basket_n"]) == "go_to_waste_basket"
    assert grounded_name(["walk_v"]) == "walk"


def test_vendored_files_match_their_provenance_note():
    """Tests that the raw files, stored gzipped, are the ones SOURCE.md lists, byte for
    byte once uncompressed."""
    note = (RAW_DIR / "SOURCE.md").read_text()
    listed = dict(re.findall(r"\| (\S+\.jsonl) \| [\d,]+ \| .*? \| ([0-9a-f]{64}) \|", note))
    assert sorted(listed) == ["lifted_stl_dev.jsonl", "lifted_stl_train.jsonl", "navi.jsonl"]
    for name, digest in listed.items():
        assert read_raw(RAW_DIR, name)[1] == digest


def test_timed_navi_style_rows_take_the_structure_of_their_grounded_formula():
    """NL2TL's lifted transcription of this row lost the parentheses that its grounded
    ``ltl`` keeps; the grounded structure is the label (row 5434 of the train file)."""
    row = {"logic_ltl": "finally ( prop_1 or prop_2 )".split(),
           "logic_sentence": "at some time ( prop_1 ) or ( prop_2 )".split(),
           "ltl": "F ( scoop_up_v pear_n ) | take_v apple_n".split()}
    (record,), _ = normalize_timed([row])
    assert record.stl == "F(prop_1) | prop_2"
    # The same predicate twice is still two lifted propositions, matched by position.
    row = {"logic_ltl": "( prop_1 imply prop_2 )".split(),
           "logic_sentence": "when ( prop_1 ) , ( prop_2 )".split(),
           "ltl": "go_by_v waste_bin_n -> go_by_v waste_bin_n".split()}
    assert lifted_from_grounded(row) == parse("prop_1 -> prop_2")


def test_timed_signal_rows_keep_their_lifted_label():
    """Signal arithmetic and empty ``ltl`` fields say nothing about structure."""
    signal = {"logic_ltl": "globally ( prop_1 imply prop_2 )".split(),
              "ltl": "G ( signal_1_n > 44.6 -> signal_2_n <= 49.9 )".split()}
    empty = {"logic_ltl": "finally [4,9] ( prop_1 )".split(), "ltl": ""}
    assert lifted_from_grounded(signal) is None and lifted_from_grounded(empty) is None


def test_timed_files_agree_with_navi_on_every_shared_sentence():
    """With the restored structure, the two NL2TL sources label every lifted sentence
    they share the same way (before, about half of the shared sentences disagreed)."""
    navi, _ = normalize_navi(read_raw(RAW_DIR, "navi.jsonl")[0])
    labels: dict[str, set[str]] = {}
    for r in navi:
        if r.form == "lifted":
            labels.setdefault(r.nl, set()).add(r.stl)
    for name in ("lifted_stl_train.jsonl", "lifted_stl_dev.jsonl"):
        timed, rejected = normalize_timed(read_raw(RAW_DIR, name)[0])
        shared = [r for r in timed if r.nl in labels]
        assert len(shared) > 1000 and rejected == []
        assert [r for r in shared if r.stl not in labels[r.nl]] == []
